#!/usr/bin/env bash
# A throwaway single-node Slurm cluster on this machine, for trying the job scripts and for
# the test that runs them (tests/slurm.rs). Needs root and the Debian packages slurmctld,
# slurmd, slurm-client and munge (tools/dev/install-slurm.sh).
#
#   tools/user/slurm/local-cluster.sh start DIR   # config, logs and state in DIR; prints the
#                                            # SLURM_CONF line for sbatch/squeue
#   tools/user/slurm/local-cluster.sh stop DIR    # stops the daemons it started, by pid
#
# Everything lives in DIR: munged gets its own socket there (the system's /run/munge is
# created only because munged expects its default folders to exist), slurmctld and slurmd
# run in the foreground as root with their pids in DIR/pids, on ports other than Slurm's
# defaults so an existing cluster is left alone. proctrack/linuxproc and task/none need no
# cgroups, which containers often lack.
set -euo pipefail

usage() { echo "usage: $0 start|stop DIR" >&2; exit 2; }
[ $# -eq 2 ] || usage
action=$1
dir=$2

stop() {
  [ -f "$dir/pids" ] || return 0
  while read -r name pid; do
    if kill -0 "$pid" 2>/dev/null; then
      kill "$pid" 2>/dev/null || true
      for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
      kill -9 "$pid" 2>/dev/null || true
    fi
    echo "stopped $name ($pid)" >&2
  done < "$dir/pids"
  rm -f "$dir/pids"
}

start() {
  for tool in munged slurmctld slurmd sinfo; do
    command -v "$tool" >/dev/null || { echo "$tool not found: run tools/dev/install-slurm.sh" >&2; exit 1; }
  done
  [ "$(id -u)" -eq 0 ] || { echo "the local cluster runs its daemons as root" >&2; exit 1; }
  mkdir -p "$dir"
  dir=$(cd "$dir" && pwd)
  chmod 700 "$dir"
  mkdir -p "$dir/state" "$dir/spool" "$dir/munge"
  chmod 700 "$dir/munge"
  mkdir -p /run/munge /var/lib/munge /var/log/munge
  : > "$dir/pids"
  # If anything below fails, do not leave daemons behind.
  trap 'stop' ERR

  local host cpus memory
  host=$(hostname -s)
  cpus=$(nproc)
  memory=$(awk '/MemTotal/ { print int($2 / 1024 * 0.9) }' /proc/meminfo)
  cat > "$dir/slurm.conf" <<EOF
ClusterName=gridtrace-local
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=16817
SlurmdPort=16818
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge/munge.socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
SlurmdTimeout=30
InactiveLimit=0
KillWait=5
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$memory State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF

  munged --foreground --force --socket="$dir/munge/munge.socket" \
    --pid-file="$dir/munge/munged.pid" --log-file="$dir/munge/munged.log" \
    --seed-file="$dir/munge/munged.seed" >"$dir/munged.out" 2>&1 &
  echo "munged $!" >> "$dir/pids"
  for _ in $(seq 100); do [ -S "$dir/munge/munge.socket" ] && break; sleep 0.1; done
  [ -S "$dir/munge/munge.socket" ] || { cat "$dir/munged.out" >&2; false; }

  slurmctld -D -i -f "$dir/slurm.conf" >"$dir/slurmctld.out" 2>&1 &
  echo "slurmctld $!" >> "$dir/pids"
  slurmd -D -f "$dir/slurm.conf" >"$dir/slurmd.out" 2>&1 &
  echo "slurmd $!" >> "$dir/pids"

  export SLURM_CONF="$dir/slurm.conf"
  for _ in $(seq 300); do
    state=$(sinfo -h -N -o '%t' 2>/dev/null | head -n1 || true)
    [ "$state" = idle ] && break
    sleep 0.2
  done
  if [ "$state" != idle ]; then
    echo "the node did not become idle (state '${state:-none}'); logs in $dir" >&2
    tail -n 20 "$dir/slurmctld.log" "$dir/slurmd.log" >&2 || true
    false
  fi
  trap - ERR
  echo "SLURM_CONF=$dir/slurm.conf"
}

case $action in
  start) start ;;
  stop) stop ;;
  *) usage ;;
esac
