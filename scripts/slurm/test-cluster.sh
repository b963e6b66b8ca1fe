#!/usr/bin/env bash
# A throw-away single-node SLURM cluster for tests, started by hand (no
# systemd): its own MUNGE daemon and key, slurmctld and slurmd, with every
# state, spool, log and socket file in DIR.
#
#   scripts/slurm/test-cluster.sh start DIR   # prints the SLURM_CONF to export
#   scripts/slurm/test-cluster.sh stop DIR    # ends the daemons it started
#
# `stop` ends only the processes `start` recorded in DIR/pids (by pid),
# never a daemon it did not start. Needs the Debian packages slurmctld,
# slurmd, slurm-client and munge, and root (slurmd runs jobs as their user).
set -euo pipefail

usage() { echo "usage: $0 start|stop DIR" >&2; exit 2; }
[ $# -eq 2 ] || usage
action=$1
dir=$2

# A TCP port nothing listens on (checked with bash's /dev/tcp).
free_port() {
    local port
    for _ in $(seq 100); do
        port=$((20000 + RANDOM % 20000))
        if ! (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null; then
            echo "$port"
            return
        fi
    done
    echo "no free TCP port found" >&2
    exit 1
}

# Waits up to $1 seconds for the command after it to succeed.
wait_for() {
    local seconds=$1
    shift
    for _ in $(seq $((seconds * 10))); do
        if "$@" >/dev/null 2>&1; then
            return 0
        fi
        sleep 0.1
    done
    return 1
}

start() {
    for tool in munged slurmctld slurmd sbatch sinfo; do
        command -v "$tool" >/dev/null || {
            echo "$tool not found: install the Debian packages munge slurmctld slurmd slurm-client" >&2
            exit 1
        }
    done
    [ "$(id -u)" -eq 0 ] || { echo "the test cluster needs root (slurmd)" >&2; exit 1; }
    [ ! -e "$dir/pids" ] || { echo "$dir/pids exists: a cluster was started there; stop it first" >&2; exit 1; }
    mkdir -p "$dir"
    dir=$(cd "$dir" && pwd)
    mkdir -p "$dir/munge" "$dir/state" "$dir/spool" "$dir/log"
    chmod 700 "$dir" "$dir/munge"
    : >"$dir/pids"

    # MUNGE with its own key and socket.
    dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
    chmod 400 "$dir/munge/munge.key"
    local socket="$dir/munge/munge.socket"
    munged --foreground --force --key-file="$dir/munge/munge.key" --socket="$socket" \
        --pid-file="$dir/munge/munged.pid" --log-file="$dir/log/munged.log" \
        --seed-file="$dir/munge/munged.seed" </dev/null >>"$dir/log/munged.out" 2>&1 &
    echo "munged $!" >>"$dir/pids"
    wait_for 10 test -S "$socket" || { echo "munged did not start: see $dir/log/munged.*" >&2; exit 1; }

    local host cpus memory user
    host=$(hostname -s)
    cpus=$(nproc)
    memory=$(slurmd -C | sed -n 's/.*RealMemory=\([0-9]*\).*/\1/p')
    user=$(id -un)
    cat >"$dir/slurm.conf" <<CONF
ClusterName=psaesptest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$(free_port)
SlurmdPort=$(free_port)
SlurmUser=$user
SlurmdUser=$user
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
ReturnToService=2
MinJobAge=600
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$memory State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
    export SLURM_CONF="$dir/slurm.conf"

    slurmctld -D -i -f "$SLURM_CONF" </dev/null >>"$dir/log/slurmctld.out" 2>&1 &
    echo "slurmctld $!" >>"$dir/pids"
    wait_for 30 scontrol ping || { echo "slurmctld did not start: see $dir/log/slurmctld.*" >&2; exit 1; }
    slurmd -D -f "$SLURM_CONF" </dev/null >>"$dir/log/slurmd.out" 2>&1 &
    echo "slurmd $!" >>"$dir/pids"
    idle() { sinfo -h -N -o %t | grep -qx idle; }
    wait_for 60 idle || { echo "the node did not come up: see $dir/log/slurmd.*" >&2; sinfo -N >&2 || true; exit 1; }
    echo "SLURM_CONF=$SLURM_CONF"
}

stop() {
    [ -e "$dir/pids" ] || { echo "$dir/pids not found: nothing was started there" >&2; exit 1; }
    # In the reverse order of starting: slurmd, slurmctld, munged.
    local pids
    pids=$(tac "$dir/pids" | awk '{print $2}')
    for pid in $pids; do
        kill -TERM "$pid" 2>/dev/null || true
    done
    for pid in $pids; do
        for _ in $(seq 100); do
            kill -0 "$pid" 2>/dev/null || break
            sleep 0.1
        done
        if kill -0 "$pid" 2>/dev/null; then
            kill -KILL "$pid" 2>/dev/null || true
        fi
    done
    rm -f "$dir/pids"
}

case $action in
start) start ;;
stop) stop ;;
*) usage ;;
esac
