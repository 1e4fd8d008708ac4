#!/usr/bin/env bash
# tools/sweep/parallel-sweep itself: 8 cases in 4 shards through GNU parallel, one shard
# failing. The script must merge the three shard files there are, name the missing shard's cases
# (1 and 5) and exit 1; the rows it has equal the single process's. Then --resume-failed reruns the
# failed shard alone and the merged table equals the single process's byte for byte.
#   parallel_sweep.sh EXC_SIM SPEC_TEMPLATE SCENE WORK
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
. "$here/sweep_test.sh"
sweep_test_setup "$@"
script=$here/../../tools/sweep/parallel-sweep
"$sim" sweep "$work/spec.yaml" --quiet --out "$work/one.jsonl"
"$sim" sweep-merge "$work/spec.yaml" "$work/one.jsonl" --out "$work/single"
# A program that dies on shard 1 of 4 before writing anything (as a lost host or a killed task does).
cat > "$work/dying-sim" <<WRAP
#!/usr/bin/env bash
case "\$*" in *"--shard 1/4"*) echo "dying-sim: shard 1 dies" >&2; exit 3;; esac
exec "$sim" "\$@"
WRAP
chmod +x "$work/dying-sim"
set +e
EXC_SIM=$work/dying-sim "$script" "$work/spec.yaml" 4 "$work/par" -j2 2> "$work/par.err"
status=$?
set -e
cat "$work/par.err"
[ "$status" -eq 1 ] || fail "parallel-sweep with a failed shard exited $status (want 1)"
[ -f "$work/par/sweep.csv" ] || fail "no merged table after a failed shard"
grep -q "1 shard(s) failed" "$work/par.err" || fail "the failed shard is not reported"
grep -q "shard-1.jsonl is not there (shard 1/4" "$work/par.err" || fail "the missing shard file is not named"
python3 - "$work/par/sweep.json" <<'PY' || fail "sweep.json does not name the missing cases 1 and 5"
import json, sys
j = json.load(open(sys.argv[1]))
assert j["missing"] == [1, 5], j["missing"]
assert j["missing_shard_files"][0]["cases"] == [1, 5], j["missing_shard_files"]
PY
# The rows the merge has are the single process's rows (all but cases 1 and 5).
grep -v -E '^(1|5),' "$work/single/sweep.csv" | cmp - "$work/par/sweep.csv" || fail "the partial table's rows differ"
# The recipe's rerun: --resume-failed runs the failed shard alone, then the table is whole.
EXC_SIM=$sim "$script" "$work/spec.yaml" 4 "$work/par" -j2 --resume-failed
[ "$(grep -c . "$work/par/joblog")" -eq 6 ] || fail "--resume-failed did not run exactly the failed shard again"
cmp "$work/single/sweep.csv" "$work/par/sweep.csv" || fail "after --resume-failed the table differs from the single process's"
echo "parallel_sweep.sh: a failed shard's cases named (1, 5), the rest merged; after --resume-failed the table equals the single process's"
