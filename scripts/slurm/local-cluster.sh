#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, for rtbench's tests and for trying the job-array scripts
# without a real cluster: Debian's slurm-wlm and munge, one node with this machine's CPUs and memory,
# job completions logged to a text file (so `sacct -c` works without slurmdbd).
#
#   bash scripts/slurm/local-cluster.sh start [DIR]    install if missing, configure, start; prints the
#                                                      `export SLURM_CONF=…` line the commands need
#   bash scripts/slurm/local-cluster.sh status [DIR]   sinfo and squeue
#   bash scripts/slurm/local-cluster.sh stop [DIR]     cancel jobs, stop the daemons, remove DIR
#
# DIR defaults to out/slurm-cluster in the repository (git-ignored). Needs root (apt-get, the daemons). Exit 3 when the cluster
# cannot be started here (not root, no apt-get, a daemon that will not come up): tests then skip,
# printing the reason.
set -euo pipefail
CMD="${1:-}"
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
DIR="${2:-$ROOT/out/slurm-cluster}"
CONF="$DIR/slurm.conf"
cannot() { echo "local-cluster.sh: cannot start a local Slurm cluster here: $*" >&2; exit 3; }
say() { echo "local-cluster.sh: $*" >&2; }

install() {
    if command -v slurmctld >/dev/null && command -v slurmd >/dev/null && command -v munged >/dev/null \
        && command -v sbatch >/dev/null; then
        return
    fi
    command -v apt-get >/dev/null || cannot "slurm-wlm and munge are missing and apt-get is not available"
    say "installing slurm-wlm and munge with apt-get"
    log="$(mktemp)"
    if ! { DEBIAN_FRONTEND=noninteractive apt-get update -qq \
        && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurm-wlm munge; } \
        >"$log" 2>&1; then
        tail -n 20 "$log" >&2; rm -f "$log"
        cannot "apt-get install slurm-wlm munge failed (output above)"
    fi
    rm -f "$log"
}

start_munge() {
    mkdir -p /etc/munge /run/munge /var/lib/munge /var/log/munge
    if [ ! -s /etc/munge/munge.key ]; then
        dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none
    fi
    if id munge >/dev/null 2>&1; then
        chown -R munge:munge /etc/munge /run/munge /var/lib/munge /var/log/munge
    fi
    chmod 0700 /etc/munge; chmod 0400 /etc/munge/munge.key
    if ! munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
        if id munge >/dev/null 2>&1; then
            runuser -u munge -- munged 2>"$DIR/munged.err" || munged --force 2>>"$DIR/munged.err" \
                || cannot "munged would not start ($(tail -n 1 "$DIR/munged.err"))"
        else
            munged --force 2>"$DIR/munged.err" || cannot "munged would not start ($(tail -n 1 "$DIR/munged.err"))"
        fi
        touch "$DIR/munged.ours"
        for _ in $(seq 50); do munge -n 2>/dev/null | unmunge >/dev/null 2>&1 && break; sleep 0.1; done
        munge -n | unmunge >/dev/null 2>&1 || cannot "munge does not answer"
    fi
}

write_conf() {
    local node cpus mem
    node="$(hostname -s)"
    cpus="$(nproc)"
    mem=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 * 9 / 10 ))
    mkdir -p "$DIR/state" "$DIR/spool"
    cat >"$CONF" <<CONF
# One-node cluster written by scripts/slurm/local-cluster.sh for rtbench's tests.
ClusterName=rtbench-local
SlurmctldHost=$node
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc=$DIR/jobcomp.txt
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU_Memory
ReturnToService=2
SlurmctldPidFile=$DIR/slurmctld.pid
SlurmdPidFile=$DIR/slurmd.pid
SlurmdSpoolDir=$DIR/spool
StateSaveLocation=$DIR/state
SlurmctldLogFile=$DIR/slurmctld.log
SlurmdLogFile=$DIR/slurmd.log
SlurmctldPort=6817
SlurmdPort=6818
MaxArraySize=10001
# Without a memory request a job would hold the whole node; a CPU's share lets tasks run side by side.
DefMemPerCPU=$((mem / cpus))
NodeName=$node CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=rtbench Nodes=$node Default=YES MaxTime=INFINITE State=UP OverSubscribe=NO
CONF
}

case "$CMD" in
start)
    [ "$(id -u)" -eq 0 ] || cannot "it needs root (apt-get and the daemons)"
    install
    mkdir -p "$DIR"
    export SLURM_CONF="$CONF"
    if [ -f "$DIR/slurmctld.pid" ] && kill -0 "$(cat "$DIR/slurmctld.pid")" 2>/dev/null; then
        say "already running"
    else
        start_munge
        write_conf
        slurmctld 2>"$DIR/slurmctld.err" || cannot "slurmctld would not start: $(tail -n 1 "$DIR/slurmctld.err")"
        slurmd 2>"$DIR/slurmd.err" || cannot "slurmd would not start: $(tail -n 1 "$DIR/slurmd.err")"
    fi
    for _ in $(seq 100); do
        state="$(sinfo -h -o %T 2>/dev/null | head -n 1 || true)"
        case "$state" in idle*|mix*|alloc*) break ;; esac
        sleep 0.2
    done
    case "${state:-}" in
        idle*|mix*|alloc*) ;;
        *) cannot "the node is '${state:-unknown}', not idle (see $DIR/slurmctld.log, $DIR/slurmd.log)" ;;
    esac
    say "cluster up: node $(hostname -s), $(nproc) CPUs, partition rtbench"
    echo "export SLURM_CONF=$CONF"
    ;;
status)
    export SLURM_CONF="$CONF"
    sinfo; squeue
    ;;
stop)
    export SLURM_CONF="$CONF"
    if [ -f "$CONF" ]; then
        scancel --user="$(id -un)" 2>/dev/null || true
        scontrol shutdown 2>/dev/null || true
        for f in slurmd slurmctld; do
            if [ -f "$DIR/$f.pid" ]; then
                pid="$(cat "$DIR/$f.pid")"
                for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
                kill "$pid" 2>/dev/null || true
            fi
        done
    fi
    if [ -f "$DIR/munged.ours" ] && [ -f /run/munge/munged.pid ]; then
        kill "$(cat /run/munge/munged.pid)" 2>/dev/null || true
    fi
    rm -rf "$DIR"
    say "stopped"
    ;;
*)
    echo "usage: bash scripts/slurm/local-cluster.sh start|status|stop [DIR]" >&2
    exit 2
    ;;
esac
