#!/usr/bin/env bash
# docs/scene_reference.md is `vdyn list --markdown` (the registered field tables): regenerate it and
# compare with the committed file. Usage: scene_reference_test.sh VDYN_BINARY SOURCE_DIR OUT_DIR
set -euo pipefail
vdyn=$1 src=$2 out=$3
mkdir -p "$out"
unset VDYN_DATA_PATH
"$vdyn" list --markdown > "$out/scene_reference.md"
if ! diff -u "$src/docs/scene_reference.md" "$out/scene_reference.md" > "$out/scene_reference.diff"; then
  head -n 40 "$out/scene_reference.diff"
  echo "docs/scene_reference.md differs from the field tables (diff above, whole diff in $out/scene_reference.diff)."
  echo "Regenerate it from the repository root: build/bin/vdyn list --markdown > docs/scene_reference.md"
  exit 1
fi
echo "docs/scene_reference.md equals vdyn list --markdown ($(grep -c '^### ' "$out/scene_reference.md") types)"
