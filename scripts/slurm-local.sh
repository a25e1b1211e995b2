#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, for the tests and for trying `dicephys slurm`:
#
#   scripts/slurm-local.sh start    munged, slurmctld and slurmd; returns when the node is idle
#   scripts/slurm-local.sh stop     stops what start started (by the ids in its pid files)
#   scripts/slurm-local.sh status   sinfo
#
# Needs root and Debian's `slurm-wlm` and `munge` (installs nothing). Its state, logs and
# slurm.conf live in $DICEPHYS_SLURM_DIR (default /tmp/dicephys-slurm); /etc/slurm/slurm.conf
# is made a link to that slurm.conf (when there is none already) so that sbatch, squeue and
# sinfo find the cluster without SLURM_CONF, and the link is removed again by stop.
set -euo pipefail

dir=${DICEPHYS_SLURM_DIR:-/tmp/dicephys-slurm}
conf=$dir/slurm.conf
etc=/etc/slurm/slurm.conf

die() { echo "slurm-local: $*" >&2; exit 1; }

need() {
  [ "$(id -u)" = 0 ] || die "run me as root (slurmd runs jobs as any user)"
  for b in munged slurmctld slurmd sinfo; do
    command -v "$b" >/dev/null || die "$b not found: apt-get install slurm-wlm munge"
  done
}

# A pid file's process, if it is still alive.
alive() { [ -s "$1" ] && kill -0 "$(cat "$1")" 2>/dev/null; }

write_conf() {
  local host node
  host=$(hostname -s)
  # This host as slurmd sees it: CPUs, sockets, cores, threads, memory.
  node=$(slurmd -C | head -1)
  case $node in NodeName=*) ;; *) die "slurmd -C did not describe this node: $node" ;; esac
  cat >"$conf" <<EOF
# Written by scripts/slurm-local.sh: a one-node cluster on $host.
ClusterName=dicephys
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
# A requeued job may start again after cred_expire seconds (default 120).
AuthInfo=cred_expire=5
StateSaveLocation=$dir/ctld
SlurmdSpoolDir=$dir/slurmd
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
SlurmctldPort=${DICEPHYS_SLURMCTLD_PORT:-6817}
SlurmdPort=${DICEPHYS_SLURMD_PORT:-6818}
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
MpiDefault=none
JobRequeue=1
ReturnToService=2
KillWait=5
MinJobAge=600
# The main scheduling loop every second, not every 60 s: a requeued task becomes eligible
# cred_expire + 1 s after its requeue but waits for that loop (a minute of the Slurm tests'
# serial chain); a batch job scheduled 1 s after its submission, not 3. One node: cheap.
SchedulerParameters=defer_batch,sched_interval=1,batch_sched_delay=1
$node State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
}

start() {
  need
  if alive "$dir/slurmctld.pid" || alive "$dir/slurmd.pid"; then
    die "already running (state in $dir); stop it first"
  fi
  mkdir -p "$dir/ctld" "$dir/slurmd"
  write_conf
  if [ -e "$etc" ] && [ "$(readlink "$etc" || true)" != "$conf" ]; then
    echo "slurm-local: $etc exists and is not ours: use SLURM_CONF=$conf" >&2
  else
    mkdir -p /etc/slurm && ln -sfn "$conf" "$etc"
  fi
  export SLURM_CONF=$conf
  # munge: reuse a running munged (its socket answers), else start one as the munge user.
  if ! munge -n </dev/null 2>/dev/null | unmunge >/dev/null 2>&1; then
    [ -s /etc/munge/munge.key ] || mungekey --create --keyfile=/etc/munge/munge.key
    chown munge:munge /etc/munge/munge.key && chmod 0400 /etc/munge/munge.key
    install -d -o munge -g munge -m 0755 /run/munge
    runuser -u munge -- munged --pid-file=/run/munge/munged.pid
    cp /run/munge/munged.pid "$dir/munged.pid"
  fi
  # -c: a clean start, no state of an earlier cluster's jobs.
  slurmctld -c -f "$conf"
  slurmd -f "$conf"
  for _ in $(seq 1 60); do
    if sinfo -h -o '%t' 2>/dev/null | grep -qx 'idle'; then
      echo "slurm-local: up ($(sinfo -h -o '%N %c CPUs %t'); state and logs in $dir)"
      echo "slurm-local: SLURM_CONF=$conf"
      return 0
    fi
    sleep 0.5
  done
  sinfo >&2 || true
  tail -n 20 "$dir/slurmctld.log" "$dir/slurmd.log" >&2 || true
  die "the node did not become idle within 30 s"
}

stop_pid() {
  local f=$1 pid
  alive "$f" || { rm -f "$f"; return 0; }
  pid=$(cat "$f")
  kill "$pid"
  for _ in $(seq 1 50); do
    kill -0 "$pid" 2>/dev/null || { rm -f "$f"; return 0; }
    sleep 0.2
  done
  kill -9 "$pid" 2>/dev/null || true
  rm -f "$f"
}

stop() {
  stop_pid "$dir/slurmd.pid"
  stop_pid "$dir/slurmctld.pid"
  stop_pid "$dir/munged.pid"
  if [ "$(readlink "$etc" 2>/dev/null || true)" = "$conf" ]; then rm -f "$etc"; fi
  echo "slurm-local: stopped"
}

case ${1:-} in
  start) start ;;
  stop) stop ;;
  status) SLURM_CONF=$conf sinfo ;;
  *) echo "usage: $0 start|stop|status" >&2; exit 2 ;;
esac
