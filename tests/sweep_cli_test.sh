#!/usr/bin/env bash
# `vdyn sweep` end to end on a small sweep of real scenes (tests/data/small.sweep.json):
#   1. --threads 2 and (if an mpirun is given) `mpirun --oversubscribe -n 3 ... --mpi`
#      give results.csv and results.json equal byte for byte to a serial run;
#   2. past the fold of the branch from straight running a row is beyond_fold (named,
#      counted apart), and a solver failure is a failed row, each with its reason;
#   3. running again resumes: nothing is run, the outputs stay the same;
#   4. its plot draws a panel per speed, the 40 m/s one (no row ok) empty and labelled.
# usage: sweep_cli_test.sh VDYN SWEEP_FILE WORK_DIR [MPIRUN]
set -euo pipefail
vdyn=$1 sweep=$2 work=$3 mpirun=${4:-}
rm -rf "$work" && mkdir -p "$work"
fail() { echo "sweep_cli_test: FAILED: $*"; exit 1; }

"$vdyn" sweep "$sweep" --threads 1 --out "$work/serial" --quiet --no-plots | tee "$work/serial.txt"
"$vdyn" sweep "$sweep" --threads 2 --out "$work/threads" --quiet --no-plots
outs=(threads)
if [ -n "$mpirun" ]; then
  OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_btl_vader_single_copy_mechanism=none \
    "$mpirun" --oversubscribe -n 3 "$vdyn" sweep "$sweep" --mpi --out "$work/mpi" --quiet --no-plots
  outs+=(mpi)
fi
for o in "${outs[@]}"; do
  for f in results.csv results.json; do
    cmp "$work/serial/$f" "$work/$o/$f" || fail "$o/$f differs from the serial run"
  done
  echo "sweep_cli_test: $o: results.csv and results.json equal to serial byte for byte"
done

# Variation 3 is past the fold (named), variation 5 a failure; the others are ok.
grep -q '^3,beyond_fold,.*no steady state on the branch from straight running: fold at front steer' \
  "$work/serial/results.csv" || fail "variation 3 is not a beyond_fold row naming the fold"
grep -q '^5,failed,.*steady state did not converge' "$work/serial/results.csv" ||
  fail "variation 5 is not a failed row naming the solver"
[ "$(grep -c ',ok,' "$work/serial/results.csv")" -eq 4 ] || fail "expected 4 ok rows"
grep -q '6 variations, 6 run now (0 from the journal), 1 failed, 1 beyond_fold;' "$work/serial.txt" ||
  fail "the console does not count 1 failed and 1 beyond_fold"
grep -q '"outcomes": {' "$work/serial/sweep_stats.json" && grep -q '"beyond_fold": 1' "$work/serial/sweep_stats.json" ||
  fail "sweep_stats.json does not count the beyond_fold row"
echo "sweep_cli_test: variation 3: $(grep '^3,' "$work/serial/results.csv" | cut -c1-160)"
echo "sweep_cli_test: variation 5: $(grep '^5,' "$work/serial/results.csv" | cut -c1-160)"

# Resume: everything is in the journal.
cp "$work/serial/results.csv" "$work/before.csv"
"$vdyn" sweep "$sweep" --threads 2 --out "$work/serial" --quiet --no-plots | tee "$work/resume.txt"
grep -q '0 run now (6 from the journal), 1 failed, 1 beyond_fold' "$work/resume.txt" || fail "the resumed sweep ran again"
cmp "$work/before.csv" "$work/serial/results.csv" || fail "resumed results differ"

# The plot (resumed again, with plots): five panels, the 40 m/s one without a point.
"$vdyn" sweep "$sweep" --threads 1 --out "$work/serial" --quiet > /dev/null
[ -s "$work/serial/yaw_rate.png" ] || fail "no yaw_rate.png"
[ "$(grep -c '^plot ' "$work/serial/yaw_rate.png.gp")" -eq 5 ] || fail "expected 5 panels in yaw_rate.png.gp"
grep -q '= 40: no point (no row ok' "$work/serial/yaw_rate.png.gp" || fail "the 40 m/s panel is not labelled empty"
echo "sweep_cli_test: passed"
