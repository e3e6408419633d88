#!/usr/bin/env bash
# Builds the data-file reader's libFuzzer target with clang (ASan + UBSan) and
# runs it for a fixed budget:  tests/fuzz/run_fuzz.sh [SECONDS=600] [JOBS=1]
# Seed corpus: tests/fuzz/corpus (in the repository); the growing corpus and
# any crash-* files go to build-fuzz/ (git-ignored). A crash is a finding: add
# its input to tests/fuzz/corpus and a test that reproduces it.
set -euo pipefail
cd "$(dirname "$0")/../.."
budget=${1:-600}
jobs=${2:-1}
out=build-fuzz
mkdir -p "$out/corpus" "$out/artifacts"
CXX=${CXX:-clang++-14}
srcs=(tests/fuzz/fuzz_params.cpp core/src/params.cpp core/src/error.cpp core/src/integrators.cpp
      core/src/scene.cpp plugins/tire/src/tire_model.cpp plugins/tire/src/road.cpp
      vehicles/common/double_wishbone.cpp)
if [ ! -x "$out/fuzz_params" ] || [ -n "$(find "${srcs[@]}" core/include plugins/tire/include vehicles/include -newer "$out/fuzz_params" | head -1)" ]; then
  echo "building $out/fuzz_params"
  $CXX -std=c++17 -O1 -g -UNDEBUG -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
    -DVDYN_DATA_DIR="\"$PWD/vehicles/data\"" -Icore/include -Iplugins/tire/include -Ivehicles/include \
    -Iplugins/steering/include -Iplugins/speed/include -Iplugins/include \
    -isystem /usr/include/simbody -isystem /usr/include/eigen3 \
    "${srcs[@]}" -lSimTKsimbody -lSimTKmath -lSimTKcommon -o "$out/fuzz_params"
fi
echo "fuzzing for ${budget} s"
UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
par=()
[ "$jobs" -gt 1 ] && par=(-fork="$jobs")
"$out/fuzz_params" "$out/corpus" tests/fuzz/corpus -max_total_time="$budget" "${par[@]}" \
  -artifact_prefix="$out/artifacts/" -print_final_stats=1 -max_len=4096 -timeout=10 2>&1 | tee "$out/fuzz.log" | tail -40
if ls "$out"/artifacts/crash-* "$out"/artifacts/leak-* "$out"/artifacts/timeout-* > /dev/null 2>&1; then
  echo "FINDINGS in $out/artifacts"; exit 1
fi
