#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, for the Slurm back end's test (issue 23), without
# systemd: munged, slurmctld and slurmd run in the foreground as background processes of
# this script, their PIDs kept in the state folder; `stop` ends them by PID.
#   bash scripts/slurm_local.sh install   apt-get install slurm-wlm (exit 3 if impossible)
#   bash scripts/slurm_local.sh start     start the cluster; prints `export SLURM_CONF=...`
#   bash scripts/slurm_local.sh stop      stop what `start` started
# State folder: $SPHEREKIT_SLURM_DIR (default /tmp/spherekit-slurm). Facts and traps:
# ../shared/docs/SCALE.md (proctrack/linuxproc + task/none in containers, short host name
# as controller, a state folder user slurm can reach, SIGKILL when SIGTERM is ignored).
set -euo pipefail
state="${SPHEREKIT_SLURM_DIR:-/tmp/spherekit-slurm}"
node=ci-node

say() { echo "slurm_local.sh: $*" >&2; }

stop_pid() {  # name: SIGTERM, then SIGKILL after 5 s (slurmd ignores SIGTERM without its controller)
  local f="$state/$1.pid"
  [[ -f "$f" ]] || return 0
  local pid
  pid="$(cat "$f")"
  if [[ -n "$pid" ]] && kill -0 "$pid" 2>/dev/null; then
    kill -TERM "$pid" 2>/dev/null || true
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -KILL "$pid" 2>/dev/null || true
  fi
  rm -f "$f"
}

case "${1:-}" in
  install)
    if command -v slurmctld >/dev/null && command -v munged >/dev/null; then exit 0; fi
    sudo=""
    [[ "$(id -u)" == 0 ]] || sudo="sudo -n"
    if ! { $sudo apt-get install -y --no-install-recommends slurm-wlm >/dev/null 2>&1 ||
           { $sudo apt-get update >/dev/null 2>&1 &&
             $sudo apt-get install -y --no-install-recommends slurm-wlm >/dev/null 2>&1; }; }; then
      say "cannot install slurm-wlm (no root or no package source)"
      exit 3
    fi
    ;;
  start)
    command -v slurmctld >/dev/null || { say "slurm-wlm is not installed"; exit 3; }
    [[ "$(id -u)" == 0 ]] || { say "needs root (munged and slurmd run as their users)"; exit 3; }
    bash "$0" stop
    # A 0755 folder: user slurm must reach its state folder (trap 2).
    mkdir -p "$state"/{state,spool,log}
    chmod 0755 "$state"
    chown slurm:slurm "$state/state"
    export USER="${USER:-root}"  # some Slurm tools read it (trap 7)
    if ! timeout 5 munge -n 2>/dev/null | timeout 5 unmunge >/dev/null 2>&1; then
      install -d -o munge -g munge -m 0755 /run/munge
      runuser -u munge -- /usr/sbin/munged --foreground </dev/null >"$state/log/munged.log" 2>&1 &
      echo $! >"$state/munged.pid"
      for _ in $(seq 50); do timeout 2 munge -n 2>/dev/null | timeout 2 unmunge >/dev/null 2>&1 && break; sleep 0.1; done
    fi
    host="$(hostname -s)"  # trap 1: the short name
    cpus="$(nproc)"
    mem="$(/usr/sbin/slurmd -C 2>/dev/null | sed -n 's/.*RealMemory=\([0-9]*\).*/\1/p')"
    mem=$(( ${mem:-2000} * 9 / 10 ))
    cat >"$state/slurm.conf" <<CONF
ClusterName=ci
SlurmctldHost=${host}(127.0.0.1)
SlurmUser=slurm
AuthType=auth/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
SchedulerParameters=sched_interval=1
StateSaveLocation=$state/state
SlurmdSpoolDir=$state/spool
SlurmctldPidFile=$state/slurmctld.pid.slurm
SlurmdPidFile=$state/slurmd.pid.slurm
SlurmctldLogFile=$state/log/slurmctld.log
SlurmdLogFile=$state/log/slurmd.log
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=ci Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
    export SLURM_CONF="$state/slurm.conf"
    /usr/sbin/slurmctld -D -f "$SLURM_CONF" </dev/null >"$state/log/slurmctld.out" 2>&1 &
    echo $! >"$state/slurmctld.pid"
    /usr/sbin/slurmd -D -N "$node" -f "$SLURM_CONF" </dev/null >"$state/log/slurmd.out" 2>&1 &
    echo $! >"$state/slurmd.pid"
    for _ in $(seq 120); do
      [[ "$(timeout 2 sinfo -h -n "$node" -o %T 2>/dev/null || true)" == idle ]] && { echo "export SLURM_CONF=$SLURM_CONF"; exit 0; }
      sleep 0.5
    done
    say "the node did not become idle in 60 s; logs in $state/log"
    bash "$0" stop
    exit 4
    ;;
  stop)
    stop_pid slurmd
    stop_pid slurmctld
    stop_pid munged
    ;;
  *)
    sed -n '2,9p' "$0" >&2
    exit 2
    ;;
esac
