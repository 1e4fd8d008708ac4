#!/usr/bin/env bash
# tools/sweep/sweep-scaling itself: 8 short cases in 4 shards with 1 and then 2 workers. It must print
# one line per worker count with its wall time and speed-up, find the two merged tables the same, and
# exit 0; a bad count is refused with exit 2. No time is asserted (the figures are the README's job).
#   sweep_scaling.sh EXC_SIM SPEC_TEMPLATE SCENE WORK
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
. "$here/sweep_test.sh"
sweep_test_setup "$@"
script=$here/../../tools/sweep/sweep-scaling
EXC_SIM=$sim "$script" "$work/spec.yaml" 4 "$work/out" 1 2 | tee "$work/lines.txt"
[ "$(grep -c '^sweep-scaling: [12] worker(s): [0-9.]* s wall, speed-up [0-9.]*x (same table)$' "$work/lines.txt")" -eq 2 ] ||
  fail "want two lines, one per worker count, each with its time, speed-up and 'same table'"
grep -q '^sweep-scaling: 1 worker(s): .* speed-up 1.00x' "$work/lines.txt" || fail "the first run is the reference (1.00x)"
[ "$(wc -l < "$work/out/j1/sweep.csv")" -eq 9 ] || fail "the merged table has not 8 cases and a header"
set +e
"$script" "$work/spec.yaml" 0 "$work/bad" 2> "$work/bad.err"
status=$?
set -e
[ "$status" -eq 2 ] || fail "SHARDS 0 exited $status (want 2)"
grep -q "got '0'" "$work/bad.err" || fail "SHARDS 0 not named in the refusal"
echo "sweep-scaling: ok"
