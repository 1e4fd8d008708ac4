#!/usr/bin/env bash
# The sweep through a real one-node Slurm cluster: the same spec run by one process and
# as a 4-task job array (tools/sweep/slurm-sweep.sbatch), merged by a job that depends on the array
# (the README's recipe), must give the same table, case for case.
#   slurm_sweep.sh EXC_SIM SPEC_TEMPLATE SCENE WORK
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
. "$here/sweep_test.sh"
sweep_test_setup "$@"
cluster=$work/cluster
trap '"$here/slurm_cluster.sh" stop "$cluster"' EXIT
"$here/slurm_cluster.sh" start "$cluster"
# shellcheck disable=SC1091
source "$cluster/env"
"$sim" sweep "$work/spec.yaml" --quiet --out "$work/one.jsonl"
"$sim" sweep-merge "$work/spec.yaml" "$work/one.jsonl" --out "$work/single"
# The README's recipe: the array, then the merge as a job that depends on it (afterany).
jid=$(sbatch --parsable --array=0-3 --output="$work/task-%a.out" \
  --export=ALL,EXC_SIM="$sim",SPEC="$work/spec.yaml",OUT="$work/slurm" "$here/../../tools/sweep/slurm-sweep.sbatch")
mid=$(sbatch --parsable --dependency=afterany:"$jid" --output="$work/merge.out" \
  --wrap "$sim sweep-merge $work/spec.yaml $work/slurm/shard-*.jsonl --out $work/merged")
# Wait for the merge job to leave the queue (bounded: the whole array takes seconds here).
for _ in $(seq 1 1200); do
  [ -z "$(squeue -h -j "$mid" 2>/dev/null)" ] && break
  sleep 0.25
done
[ -z "$(squeue -h -j "$mid" 2>/dev/null)" ] || fail "the merge job $mid is still queued after 300 s"
cat "$work/merge.out"
for i in 0 1 2 3; do [ -s "$work/slurm/shard-$i.jsonl" ] || fail "task $i wrote no shard file"; done
[ -f "$work/merged/sweep.csv" ] || fail "the merge job wrote no table (see $work/merge.out)"
if cmp "$work/single/sweep.csv" "$work/merged/sweep.csv"; then
  echo "slurm_sweep.sh: the job array's merged table equals the single process's ($(($(wc -l < "$work/merged/sweep.csv") - 1)) cases)"
else
  fail "the job array's table differs from the single process's"
fi
