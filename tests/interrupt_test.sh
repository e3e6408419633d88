#!/usr/bin/env bash
# SIGINT on `vdyn sweep` and `vdyn run` (item 5 of issue 23):
#   1. a sweep interrupted after its first journal line exits 130 with one line,
#      leaves runs.jsonl and a results.csv of the finished rows only, marked
#      "partial": true in sweep_stats.json and results.json;
#   2. running it again resumes and gives results.csv equal byte for byte to a
#      clean run's;
#   3. a transient `vdyn run` interrupted mid-run exits 130 with one line saying
#      where it stopped, and writes no summary.json.
# usage: interrupt_test.sh VDYN WORK_DIR
set -uo pipefail
vdyn=$1 work=$2
rm -rf "$work" && mkdir -p "$work"
fail() { echo "interrupt_test: FAILED: $*"; exit 1; }

# Twelve steady turns (the chapter 3 scene) at 6..17 m/s.
cat > "$work/twelve.sweep.json" <<JSON
{"scene": "scenes/ch3_steady_state.json", "set": {"analysis.stability": false},
 "variations": [{"grid": [{"keys": ["vehicle.initial_speed_m_s", "plugins.speed_hold.speed_m_s"],
   "values": [[6, 6], [7, 7], [8, 8], [9, 9], [10, 10], [11, 11], [12, 12], [13, 13], [14, 14], [15, 15],
              [16, 16], [17, 17]]}]}],
 "collect": ["steady.chassis.yaw_rate_rad_s", "newton_iterations"]}
JSON
"$vdyn" sweep "$work/twelve.sweep.json" --threads 1 --quiet --no-plots --out "$work/clean" > /dev/null ||
  fail "the clean sweep failed"

"$vdyn" sweep "$work/twelve.sweep.json" --threads 1 --quiet --no-plots --out "$work/cut" \
  > "$work/cut.out" 2> "$work/cut.err" &
pid=$!
# Wait (no timing assumption) for the first finished variation, then interrupt.
for _ in $(seq 1 6000); do
  [ -s "$work/cut/runs.jsonl" ] && break
  kill -0 $pid 2> /dev/null || break
  sleep 0.01
done
kill -INT $pid
wait $pid
rc=$?
echo "interrupt_test: sweep exit $rc, stderr: $(cat "$work/cut.err")"
[ $rc -eq 130 ] || fail "exit code $rc, expected 130"
[ "$(wc -l < "$work/cut.err")" -eq 1 ] || fail "stderr is not one line"
grep -q '^vdyn sweep: interrupted by SIGINT: [0-9]* of 12 variations done, in .*/results.csv (partial: true' "$work/cut.err" ||
  fail "the line does not say what was done"
done_rows=$(($(wc -l < "$work/cut/results.csv") - 1))
journal=$(wc -l < "$work/cut/runs.jsonl")
[ $done_rows -ge 1 ] && [ $done_rows -lt 12 ] || fail "results.csv has $done_rows rows, expected 1..11"
[ $done_rows -eq "$journal" ] || fail "results.csv has $done_rows rows, the journal $journal"
grep -q '"partial": true' "$work/cut/sweep_stats.json" || fail "sweep_stats.json is not marked partial"
grep -q '"interrupted_by": "SIGINT"' "$work/cut/sweep_stats.json" || fail "sweep_stats.json does not name SIGINT"
grep -q '"partial": true' "$work/cut/results.json" || fail "results.json is not marked partial"
head -n $((done_rows + 1)) "$work/clean/results.csv" | cmp - "$work/cut/results.csv" ||
  fail "the partial rows differ from the clean run's"
echo "interrupt_test: partial results.csv: $done_rows of 12 rows, journal $journal lines"

"$vdyn" sweep "$work/twelve.sweep.json" --threads 1 --quiet --no-plots --out "$work/cut" > "$work/resume.out" ||
  fail "the resumed sweep failed"
grep -q "$((12 - done_rows)) run now ($done_rows from the journal)" "$work/resume.out" || fail "did not resume: $(cat "$work/resume.out")"
cmp "$work/clean/results.csv" "$work/cut/results.csv" || fail "resumed results.csv differs from the clean run's"
cmp "$work/clean/results.json" "$work/cut/results.json" || fail "resumed results.json differs from the clean run's"
grep -q '"partial": false' "$work/cut/sweep_stats.json" || fail "the resumed sweep is still marked partial"
echo "interrupt_test: resumed: results.csv and results.json equal to the clean run byte for byte"

# vdyn run: a 100 s transient, interrupted once its output folder exists.
"$vdyn" run scenes/ch3_transient.json --no-plots --set analysis.t_end_s=100 --out "$work/run" \
  > "$work/run.out" 2> "$work/run.err" &
pid=$!
for _ in $(seq 1 6000); do
  [ -d "$work/run" ] && break
  sleep 0.01
done
sleep 0.2  # into the integration (the signal is honoured at the next step either way)
kill -INT $pid
wait $pid
rc=$?
echo "interrupt_test: run exit $rc, stderr: $(cat "$work/run.err")"
[ $rc -eq 130 ] || fail "vdyn run exit code $rc, expected 130"
[ "$(wc -l < "$work/run.err")" -eq 1 ] || fail "vdyn run stderr is not one line"
grep -q '^vdyn run: interrupted by SIGINT at t = .* s of the run to t_end 100 s; nothing written to ' "$work/run.err" ||
  fail "vdyn run does not say where it stopped"
[ ! -e "$work/run/summary.json" ] || fail "an interrupted run wrote summary.json"
! grep -q "summary.json" "$work/run.out" || fail "an interrupted run printed a written line"
echo "interrupt_test: passed"
