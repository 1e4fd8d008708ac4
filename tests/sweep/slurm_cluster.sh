#!/usr/bin/env bash
# slurm_cluster.sh start DIR | stop DIR: a one-node Slurm cluster on this host for the sweep test
# (docs/sweeps.md): munge with a key of its own, slurmctld and slurmd as plain daemons (no systemd),
# all state, spool and logs under DIR; `source DIR/env` sets SLURM_CONF for sbatch and sinfo.
# Root only. Exit 0 once `sinfo` shows the node idle; 1 with the daemons' logs otherwise.
set -euo pipefail
cmd=${1:-} dir=${2:-}
[ -n "$cmd" ] && [ -n "$dir" ] || { echo "usage: slurm_cluster.sh start|stop DIR" >&2; exit 2; }
dir=$(realpath -m "$dir")
stop() {
  for p in slurmd slurmctld munged; do
    [ -f "$dir/$p.pid" ] && kill "$(cat "$dir/$p.pid")" 2>/dev/null || true
  done
  sleep 1
  for p in slurmd slurmctld munged; do
    [ -f "$dir/$p.pid" ] && kill -9 "$(cat "$dir/$p.pid")" 2>/dev/null || true
    rm -f "$dir/$p.pid"
  done
}
if [ "$cmd" = stop ]; then stop; exit 0; fi
[ "$cmd" = start ] || { echo "slurm_cluster.sh: unknown command $cmd" >&2; exit 2; }
for p in munged slurmctld slurmd sbatch sinfo; do
  command -v "$p" > /dev/null || { echo "slurm_cluster.sh: $p not found: apt-get install slurm-wlm munge" >&2; exit 1; }
done
stop 2>/dev/null || true
rm -rf "$dir"
mkdir -p "$dir"/{munge,spool,state,log}
chown munge: "$dir/munge"; chmod 700 "$dir/munge"
# munge: a key of its own and a socket in DIR, so a system munged (if any) is left alone.
dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
chown munge: "$dir/munge/munge.key"; chmod 400 "$dir/munge/munge.key"
sock=$dir/munge/munge.socket
su -s /bin/sh munge -c "munged --key-file='$dir/munge/munge.key' --socket='$sock' --pid-file='$dir/munge/munged.pid' --log-file='$dir/munge/munged.log' --seed-file='$dir/munge/seed' --force" 
cp "$dir/munge/munged.pid" "$dir/munged.pid" 2>/dev/null || true
host=$(hostname -s)
cpus=$(nproc)
mem=$(( $(awk '/MemAvailable/ {print $2}' /proc/meminfo) / 1024 / 2 ))
cat > "$dir/slurm.conf" <<CONF
ClusterName=exc
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
AuthType=auth/munge
AuthInfo=socket=$sock
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
SlurmctldPort=6917
SlurmdPort=6918
ReturnToService=2
MpiDefault=none
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=sweep Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
echo "export SLURM_CONF=$dir/slurm.conf" > "$dir/env"
export SLURM_CONF=$dir/slurm.conf
slurmctld -i
slurmd
for i in $(seq 1 60); do
  if sinfo -h -o '%T' 2>/dev/null | grep -q '^idle'; then echo "slurm_cluster.sh: node $host idle"; exit 0; fi
  sleep 0.5
done
echo "slurm_cluster.sh: the node did not come up; logs:" >&2
tail -n 20 "$dir"/log/*.log "$dir/munge/munged.log" >&2 || true
stop
exit 1
