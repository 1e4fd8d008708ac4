#!/usr/bin/env bash
# The sweep through a real one-node Slurm cluster (issue 17): the same spec run by one process and
# as a 4-task job array (tools/sweep/slurm-sweep.sbatch) must merge to the same table, case for case.
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
sbatch --wait --array=0-3 --output="$work/task-%a.out" \
  --export=ALL,EXC_SIM="$sim",SPEC="$work/spec.yaml",OUT="$work/slurm" "$here/../../tools/sweep/slurm-sweep.sbatch"
"$sim" sweep-merge "$work/spec.yaml" "$work"/slurm/shard-{0,1,2,3}.jsonl --out "$work/merged"
if cmp "$work/single/sweep.csv" "$work/merged/sweep.csv"; then
  echo "slurm_sweep.sh: the job array's merged table equals the single process's ($(($(wc -l < "$work/merged/sweep.csv") - 1)) cases)"
else
  echo "FAIL: the job array's table differs from the single process's" >&2
  exit 1
fi
