#!/usr/bin/env bash
# Builds the data-file reader's libFuzzer target with clang (ASan + UBSan) and
# runs it for a fixed budget:  tests/fuzz/run_fuzz.sh [SECONDS=600] [JOBS=1]
# Seed corpus: tests/fuzz/corpus (hand-made nested, oversized and malformed
# inputs) and the shipped data files themselves, vehicles/data (read
# recursively, so the seeds never go stale against the data), dictionary tests/fuzz/json.dict; inputs up to 256 KiB
# (-max_len: deep nesting needs length); the growing corpus and
# any crash-* files go to build-fuzz/ (git-ignored). A crash is a finding: add
# its input to tests/fuzz/corpus and a test that reproduces it.
set -euo pipefail
cd "$(dirname "$0")/../.."
budget=${1:-600}
jobs=${2:-1}
out=build-fuzz
mkdir -p "$out/corpus" "$out/artifacts"
CXX=${CXX:-clang++-14}
# The reader's own files are compiled here with coverage and sanitizers; the
# rest (Simbody models, plugins) comes from the Release build's libraries
# (bash .ci/build first), whose definitions the instrumented ones override.
srcs=(tests/fuzz/fuzz_params.cpp core/src/params.cpp core/src/scene_file.cpp core/src/error.cpp
      vehicles/scene/standard_registry.cpp)
[ -f build/lib/libvdyn_vehicles.so ] || { echo "run bash .ci/build first (the fuzz target links build/lib)"; exit 2; }
if [ ! -x "$out/fuzz_params" ] || [ -n "$(find "${srcs[@]}" core/include -newer "$out/fuzz_params" | head -1)" ]; then
  echo "building $out/fuzz_params"
  incs=()
  for d in core/include plugins/include plugins/*/include vehicles/include; do incs+=(-I"$d"); done
  libs=()
  for l in build/lib/libvdyn_*.so; do
    case $l in *fixture*) ;; *) libs+=("$PWD/$l") ;; esac
  done
  $CXX -std=c++17 -O1 -g -UNDEBUG -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
    -DVDYN_BUILD_DATA_DIR="\"$PWD/vehicles/data\"" -DVDYN_LIB_TO_DATA="\"../share/vdyn/data\"" "${incs[@]}" \
    -isystem /usr/include/simbody -isystem /usr/include/eigen3 \
    "${srcs[@]}" "${libs[@]}" -Wl,-rpath,"$PWD/build/lib" -lSimTKsimbody -lSimTKmath -lSimTKcommon -ldl \
    -o "$out/fuzz_params"
fi
echo "fuzzing for ${budget} s"
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
par=()
[ "$jobs" -gt 1 ] && par=(-fork="$jobs")
"$out/fuzz_params" "$out/corpus" tests/fuzz/corpus vehicles/data -max_total_time="$budget" "${par[@]}" \
  -artifact_prefix="$out/artifacts/" -print_final_stats=1 -dict=tests/fuzz/json.dict -max_len=262144 -len_control=20 \
  -timeout=10 2>&1 | tee "$out/fuzz.log" | tail -40
if ls "$out"/artifacts/crash-* "$out"/artifacts/leak-* "$out"/artifacts/timeout-* > /dev/null 2>&1; then
  echo "FINDINGS in $out/artifacts"; exit 1
fi
