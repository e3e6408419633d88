#!/bin/sh
# Runs one case of the bad-input catalogue (cases.txt; format in generate_cases.py):
#   run_case.sh BIN_DIR DATA_DIR CASES_FILE NAME
# Passes when the program exits with the expected code, its stderr is one line
# holding the expected text, and a failed run left no summary.json claiming
# "completed": true.
bin=$1 data=$2 cases=$3 name=$4
line=$(awk -F ' [|] ' -v n="$name" '$1 == n { print; exit }' "$cases")
[ -n "$line" ] || { echo "no case '$name' in $cases"; exit 2; }
field() { printf '%s\n' "$line" | awk -F ' [|] ' -v i="$1" '{ print $i }'; }
rc_want=$(field 2) text=$(field 3) json=$(field 4) cmd=$(field 5)
tmp=$(mktemp -d) || exit 2
trap 'chmod -R u+w "$tmp" 2>/dev/null; rm -rf "$tmp"' EXIT
cd "$tmp" || exit 2
[ "$json" != "-" ] && printf '%s' "$json" > case.json
printf '{"based_on": "ch3_transient.json", "vehicle_data": "%s/case.json"}' "$tmp" > ch3.json
touch afile
mkdir -p out
# An unwritable folder: root ignores permission bits, so use /proc there.
if [ "$(id -u)" -eq 0 ]; then ro=/proc; else mkdir ro && chmod 555 ro && ro=$tmp/ro; fi
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
eval "set -- $args"
"$bin/$prog" "$@" > stdout.txt 2> stderr.txt
rc=$?
ok=1
[ "$rc" = "$rc_want" ] || { echo "exit code $rc, expected $rc_want"; ok=0; }
grep -qF -- "$text" stderr.txt || { echo "stderr lacks: $text"; ok=0; }
[ "$(wc -l < stderr.txt)" -le 1 ] || { echo "stderr has more than one line"; ok=0; }
if [ "$rc" != 0 ] && [ -f out/summary.json ] && grep -q '"completed": true' out/summary.json && ! grep -q '"steady": false' out/summary.json; then
  echo "a failed run left a summary.json that claims completion"; ok=0
fi
echo "command: $prog $*"; echo "--- stderr"; cat stderr.txt
[ $ok = 1 ]
