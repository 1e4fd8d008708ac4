#!/usr/bin/env bash
# The sweep's progress as a person sees it: on a terminal (a pseudo-terminal from script(1)) a line
# "k of N cases, elapsed, ~time left"; in a pipe or a log, none; parallel-sweep's line the same, in
# cases over every shard. parallel-sweep names a spec that does not load once (not once per shard and
# again for the merge) and exits 2.
#   sweep_progress.sh EXC_SIM SPEC_TEMPLATE SCENE WORK
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
. "$here/sweep_test.sh"
sweep_test_setup "$@"
script=$here/../../tools/sweep/parallel-sweep
sed -i 's/cases: 8/cases: 3/' "$work/spec.yaml"
# On a terminal: the count of cases, the total, the time taken and left.
script -qfec "'$sim' sweep '$work/spec.yaml' --out '$work/tty.jsonl'" /dev/null > "$work/tty.txt"
cat "$work/tty.txt"
grep -q "sweep: 3 of 3 cases, [0-9]* s elapsed" "$work/tty.txt" || fail "no final progress line 'sweep: 3 of 3 cases, ... elapsed' on a terminal"
grep -q "of 3 cases" "$work/tty.txt" || fail "the progress line does not give the total"
# In a pipe: quiet.
"$sim" sweep "$work/spec.yaml" --out "$work/pipe.jsonl" 2> "$work/pipe.err" > /dev/null
if grep -q "cases," "$work/pipe.err"; then fail "a progress line where stderr is no terminal: $(cat "$work/pipe.err")"; fi
# parallel-sweep on a terminal: the cases (3), not the shards (2), done of the total, the time taken.
EXC_SIM=$sim script -qfec "'$script' '$work/spec.yaml' 2 '$work/par' -j2" /dev/null > "$work/par-tty.txt"
cat "$work/par-tty.txt"
grep -q "parallel-sweep: 3 of 3 cases, [0-9]* s elapsed" "$work/par-tty.txt" ||
  fail "parallel-sweep shows no final line 'parallel-sweep: 3 of 3 cases, ... elapsed' on a terminal: $(cat "$work/par-tty.txt")"
if grep -q "of 2 cases\|Left: " "$work/par-tty.txt"; then fail "parallel-sweep counts shards, not cases"; fi
[ -f "$work/par/sweep.csv" ] || fail "parallel-sweep on a terminal did not merge"
# In a pipe: quiet.
EXC_SIM=$sim "$script" "$work/spec.yaml" 2 "$work/par-pipe" -j2 2> "$work/par-pipe.err" > /dev/null
if grep -q "cases,\|ETA" "$work/par-pipe.err"; then fail "parallel-sweep shows progress where stderr is no terminal: $(cat "$work/par-pipe.err")"; fi
[ -f "$work/par-pipe/sweep.csv" ] || fail "parallel-sweep in a pipe did not merge"
# A spec that does not load: its error once, exit 2, no shard run.
sed 's/cases: 3/cases: -3/' "$work/spec.yaml" > "$work/bad.yaml"
set +e
EXC_SIM=$sim "$script" "$work/bad.yaml" 4 "$work/bad" -j2 2> "$work/bad.err"
status=$?
set -e
cat "$work/bad.err"
[ "$status" -eq 2 ] || fail "parallel-sweep with a bad spec exited $status (want 2)"
[ "$(grep -c "bad.yaml" "$work/bad.err")" -eq 1 ] || fail "the bad spec's error is not printed exactly once"
[ ! -e "$work/bad/joblog" ] || fail "shards ran on a bad spec"
echo "sweep_progress.sh: the progress line on a terminal only, with its total and time left (parallel-sweep's in cases); a bad spec named once"
