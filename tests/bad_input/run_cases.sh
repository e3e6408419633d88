#!/bin/sh
# Runs a shard of the bad-input catalogue (cases.txt; format in generate_cases.py):
#   run_cases.sh BIN_DIR DATA_DIR CASES_FILE SHARD NSHARDS
# runs every case whose line number (among the cases) modulo NSHARDS is SHARD,
# one after the other, and fails when one fails (each failure is printed with
# its name, command and stderr). A case passes when the program exits with the
# expected code, its stderr is one line holding the expected text, and a failed
# run left no summary.json claiming "completed": true.
# One ctest per shard (not per case): the cases run in parallel shards without
# a ctest and shell start-up per case.
bin=$1 data=$2 cases=$3 shard=$4 nshards=$5
[ -n "$nshards" ] || { echo "usage: run_cases.sh BIN_DIR DATA_DIR CASES_FILE SHARD NSHARDS"; exit 2; }
root=$(mktemp -d) || exit 2
trap 'chmod -R u+w "$root" 2>/dev/null; rm -rf "$root"' EXIT
passed=0 failed=0 i=0 failures=""
# An unwritable folder: root ignores permission bits, so use /proc there.
if [ "$(id -u)" -eq 0 ]; then ro=/proc; else mkdir "$root/ro" && chmod 555 "$root/ro" && ro=$root/ro; fi
SEP=$(printf '\037')  # a non-blank separator: read keeps empty fields (an empty data file)
# name, exit, text, json, command (fields separated by ' | ') -> SEP-separated for read
sed -e '/^#/d' -e '/ | /!d' -e "s/ | /$SEP/g" "$cases" > "$root/cases.tsv"
while IFS="$SEP" read -r name rc_want text json cmd; do
  i=$((i + 1))
  [ $(( (i - 1) % nshards )) -eq "$shard" ] || continue
  tmp=$root/c$i
  mkdir -p "$tmp/out"
  [ "$json" != "-" ] && printf '%s' "$json" > "$tmp/case.json"
  printf '{"based_on": "scenes/ch3_transient.json", "vehicle": {"data": "%s/case.json"}}' "$tmp" > "$tmp/ch3.json"
  touch "$tmp/afile"
  sub() {
    printf '%s' "$1" | sed -e "s|{CASE}|$tmp/case.json|g" -e "s|{CH3CASE}|$tmp/ch3.json|g" -e "s|{OUT}|$tmp/out|g" \
      -e "s|{DATA}|$data|g" -e "s|{TMP}|$tmp|g" -e "s|{RO}|$ro|g" -e "s|{FILE}|$tmp/afile|g"
  }
  cmd=$(sub "$cmd")
  text=$(sub "$text")
  # {FULL:name}: the temporary file of out/name is /dev/full (a full disk).
  for f in $(printf '%s' "$cmd" | grep -o '{FULL:[^}]*}'); do
    target=$(printf '%s' "$f" | sed 's/{FULL:\(.*\)}/\1/')
    ln -s /dev/full "$tmp/out/$target.tmp"
    cmd=$(printf '%s' "$cmd" | sed "s|$f||")
  done
  prog=${cmd%% *}
  args=${cmd#"$prog"}
  (cd "$tmp" && eval "set -- $args" && exec "$bin/$prog" "$@" > stdout.txt 2> stderr.txt)
  rc=$?
  why=""
  [ "$rc" = "$rc_want" ] || why="$why; exit code $rc, expected $rc_want"
  grep -qF -- "$text" "$tmp/stderr.txt" || why="$why; stderr lacks: $text"
  # (vdyn check lists every error it finds, one per line)
  [ "$prog" = vdyn ] && [ "${args# check}" != "$args" ] ||
    [ "$(wc -l < "$tmp/stderr.txt")" -le 1 ] || why="$why; stderr has more than one line"
  if [ "$rc" != 0 ] && [ -f "$tmp/out/summary.json" ] && grep -q '"completed": true' "$tmp/out/summary.json" &&
     ! grep -q '"steady": false' "$tmp/out/summary.json"; then
    why="$why; a failed run left a summary.json that claims completion"
  fi
  if [ -z "$why" ]; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAILED $name${why}"
    echo "  command: $prog$args"
    echo "  stderr: $(cat "$tmp/stderr.txt")"
  fi
  chmod -R u+w "$tmp" 2>/dev/null
  rm -rf "$tmp"
done < "$root/cases.tsv"
echo "bad-input shard $shard of $nshards: $passed passed, $failed failed"
[ "$failed" -eq 0 ] && [ "$passed" -gt 0 ]
