#!/usr/bin/env bash
# A one-node SLURM cluster on this machine, for trying the slurm profile (and for tests/test_slurm.py).
#
#   profiles/slurm/cluster.sh up [DIR]    start munged, slurmctld and slurmd with everything in DIR
#                                         (a new temporary folder if not given); prints DIR, then the
#                                         line `export SLURM_CONF=DIR/slurm.conf PATH=DIR/bin:$PATH` that
#                                         points sbatch, squeue, srun (and snakemake) at it
#   profiles/slurm/cluster.sh down DIR    cancel its jobs and stop its daemons (DIR and its logs stay)
#
# Any other use (an option such as --help where DIR goes, too: a folder named -x is ./-x) prints
# `cluster.sh: error: usage: profiles/slurm/cluster.sh up [DIR] | down DIR`.
# `up` checks DIR before it installs or starts anything: a folder to make or one without a cluster
# (an existing file, a folder that already holds a cluster, white space, a munge socket path over
# 107 characters, or a folder above DIR that not every user may enter, as munged requires, are
# refused). `down` signals only the daemons this script started for DIR: the
# process a pid file names is signalled only while its command is that daemon's with DIR's own file
# as an argument (DIR/slurm.conf; munged's --pid-file=DIR/munged.pid). A stale pid file, whose pid
# a reboot gave to another process, is left alone with a note.
#
# Needs root (the daemons run as root and so do the jobs) and Debian's packages slurmctld, slurmd,
# slurm-client and munge; missing packages are installed with apt-get, which waits up to 10 minutes
# for another package manager's lock (DPkg::Lock::Timeout). Nothing outside DIR is
# written or read besides that: its own munge key and socket, free TCP ports, and no accounting
# database (the executor reads job states from squeue, so MinJobAge keeps finished jobs for an hour;
# the job completion log DIR/jobcomp.log records every job). The node is this machine, with the CPUs
# and memory `slurmd -C` finds. Any failure is one line `cluster.sh: error: ...` and exit status 1.
set -euo pipefail

started=""  # the folder of a cluster being started: a failure stops what already runs there
USAGE="usage: $0 up [DIR] | down DIR"
APT=(apt-get -o DPkg::Lock::Timeout=600)

die() {
    echo "cluster.sh: error: $*" >&2
    if [ -n "$started" ]; then stop_daemons "$started"; fi
    exit 1
}

need_packages() {
    local missing=()
    for cmd in munged slurmctld slurmd sbatch squeue scontrol sinfo; do
        command -v "$cmd" > /dev/null 2>&1 || missing+=("$cmd")
    done
    [ ${#missing[@]} -eq 0 ] && return 0
    command -v apt-get > /dev/null 2>&1 \
        || die "missing ${missing[*]} and no apt-get to install Debian's slurmctld slurmd slurm-client munge"
    local log
    log=$(mktemp)
    if ! { DEBIAN_FRONTEND=noninteractive "${APT[@]}" install -y -q slurmctld slurmd slurm-client munge > "$log" 2>&1 \
           || { "${APT[@]}" update -q > "$log" 2>&1 \
                && DEBIAN_FRONTEND=noninteractive "${APT[@]}" install -y -q slurmctld slurmd slurm-client munge > "$log" 2>&1; }; }; then
        local last
        last=$(grep -E '^(E|W):' "$log" | tail -n 1 || true)
        rm -f "$log"
        die "apt-get could not install slurmctld slurmd slurm-client munge: ${last:-see apt-get output}"
    fi
    rm -f "$log"
    for cmd in "${missing[@]}"; do
        command -v "$cmd" > /dev/null 2>&1 || die "apt-get installed the packages but $cmd is still missing"
    done
}

free_port() {
    python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}

# last line of a daemon's log, for the error message
last_log() { [ -s "$1" ] && tail -n 1 "$1" | cut -c1-200 || echo "no log written"; }

wait_pid_file() {  # FILE NAME LOG: the daemon wrote its pid and is alive
    for _ in $(seq 1 100); do
        if [ -s "$1" ] && kill -0 "$(cat "$1")" 2> /dev/null; then return 0; fi
        sleep 0.1
    done
    die "$2 did not start: $(last_log "$3")"
}

check_new_dir() {  # DIR: a folder up can make or use, checked before anything is installed or started
    local dir=$1 abs parent
    case $dir in *[[:space:]]*) die "DIR '$dir' contains white space, which slurm.conf cannot hold; choose another folder" ;; esac
    if [ -e "$dir" ] && [ ! -d "$dir" ]; then
        die "DIR '$dir' exists and is not a folder; give a folder to make or one without a cluster"
    fi
    [ ! -e "$dir/slurm.conf" ] || die "$dir already holds a cluster (run: $0 down $dir)"
    parent=$dir
    while [ ! -e "$parent" ]; do parent=$(dirname -- "$parent"); done
    [ -d "$parent" ] || die "DIR '$dir' cannot be made: '$parent' is not a folder"
    [ -w "$parent" ] || die "DIR '$dir' cannot be made: '$parent' is not writable"
    abs=$(realpath -m -- "$dir")
    [ ${#abs} -le 94 ] || die "DIR '$abs' is ${#abs} characters long; at most 94 (munge's socket DIR/munge.socket must fit a 107-character socket path)"
    local up_dir=$abs  # munged wants every folder above its socket searchable by all
    while [ "$up_dir" != / ]; do
        up_dir=$(dirname -- "$up_dir")
        if [ -d "$up_dir" ] && [ "$(( 0$(stat -c %a -- "$up_dir") & 1 ))" -eq 0 ]; then
            die "DIR '$dir' is inside '$up_dir', which not every user may enter (mode $(stat -c %a -- "$up_dir")); munged needs that for its socket: choose another folder or chmod o+x '$up_dir'"
        fi
    done
}

up() {
    local dir=${1:-}
    # (without DIR: the folder mktemp will make in TMPDIR, checked the same way)
    check_new_dir "${dir:-${TMPDIR:-/tmp}/slurm-cluster.XXXXXX}"
    [ "$(id -u)" -eq 0 ] || die "needs root to run munged, slurmctld and slurmd (running as uid $(id -u))"
    need_packages
    if [ -z "$dir" ]; then dir=$(mktemp -d "${TMPDIR:-/tmp}/slurm-cluster.XXXXXX"); fi
    mkdir -p -- "$dir" 2> /dev/null || die "DIR '$dir' could not be made"
    dir=$(cd -- "$dir" && pwd)
    [ ! -e "$dir/slurm.conf" ] || die "$dir already holds a cluster (run: $0 down $dir)"
    chmod 755 "$dir"  # munged wants its socket's folders searchable by all
    mkdir -p "$dir/state" "$dir/spool"

    started=$dir
    # munge with its own key and socket: nothing shared with a system munged or another cluster
    head -c 1024 /dev/urandom > "$dir/munge.key"
    chmod 400 "$dir/munge.key"
    munged --socket="$dir/munge.socket" --key-file="$dir/munge.key" --pid-file="$dir/munged.pid" \
        --log-file="$dir/munged.log" --seed-file="$dir/munged.seed" 2> "$dir/munged.err" \
        || die "munged did not start: $(last_log "$dir/munged.err")"
    wait_pid_file "$dir/munged.pid" munged "$dir/munged.log"

    local node host ctld_port slurmd_port
    node=$(slurmd -C | head -n 1)
    [[ $node == NodeName=* ]] || die "slurmd -C did not describe this machine: $node"
    host=${node%% *}
    host=${host#NodeName=}
    ctld_port=$(free_port)
    slurmd_port=$(free_port)
    while [ "$slurmd_port" = "$ctld_port" ]; do slurmd_port=$(free_port); done
    cat > "$dir/slurm.conf" << EOF
ClusterName=msslib
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge.socket
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc=$dir/jobcomp.log
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU_Memory
MpiDefault=none
ReturnToService=2
MinJobAge=3600
MailProg=/bin/true
${node%% UpTime=*} NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=main Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
    export SLURM_CONF="$dir/slurm.conf"
    # The executor's job step starts its srun without SLURM_* variables (SLURM_CONF included), so that
    # srun would look for the machine's own configuration: DIR/bin/srun (first on PATH) points it here.
    mkdir -p "$dir/bin"
    printf '#!/bin/sh\nexport SLURM_CONF=%s\nexec %s "$@"\n' "$SLURM_CONF" "$(command -v srun)" > "$dir/bin/srun"
    chmod 755 "$dir/bin/srun"
    slurmctld -f "$SLURM_CONF" -c 2> "$dir/slurmctld.err" || die "slurmctld did not start: $(last_log "$dir/slurmctld.err")"
    wait_pid_file "$dir/slurmctld.pid" slurmctld "$dir/slurmctld.log"
    slurmd -f "$SLURM_CONF" -N "$host" 2> "$dir/slurmd.err" || die "slurmd did not start: $(last_log "$dir/slurmd.err")"
    wait_pid_file "$dir/slurmd.pid" slurmd "$dir/slurmd.log"

    local state=""
    for _ in $(seq 1 150); do
        state=$(sinfo -h -N -n "$host" -o %T 2> /dev/null || true)
        [ "$state" = idle ] && break
        sleep 0.2
    done
    [ "$state" = idle ] || die "node $host is '${state:-not reported}', not idle, after 30 s: $(last_log "$dir/slurmctld.log")"
    started=""
    echo "$dir"
    echo "export SLURM_CONF=$SLURM_CONF PATH=$dir/bin:\$PATH"
}

owned_pid() {  # FILE NAME DIR: prints the pid FILE names if that process is NAME started for DIR
    [ -s "$1" ] || return 1
    local pid cmd
    pid=$(head -c 32 "$1" | tr -d '[:space:]')
    [[ $pid =~ ^[1-9][0-9]*$ ]] || return 1
    [ -r "/proc/$pid/cmdline" ] || return 1
    cmd=$(tr '\0' '\n' < "/proc/$pid/cmdline" 2> /dev/null) || return 1
    [ "$(basename -- "${cmd%%$'\n'*}")" = "$2" ] || return 1  # the program
    # started for DIR: one of its arguments is exactly the one up gave it (not merely a path under DIR,
    # which a cluster in a sub-folder of DIR also has)
    local own="$3/slurm.conf"
    [ "$2" = munged ] && own="--pid-file=$3/munged.pid"
    grep -qxF -- "$own" <<< "$cmd" || return 1
    echo "$pid"
}

stop_pid_file() {  # FILE NAME DIR: SIGTERM, then SIGKILL after 10 s, to NAME of DIR only
    [ -s "$1" ] || return 0
    local pid
    if ! pid=$(owned_pid "$1" "$2" "$3"); then
        echo "cluster.sh: note: $1 names pid $(head -c 32 "$1" | tr -d '[:space:]'), not $2 of $3; left alone" >&2
        return 0
    fi
    kill "$pid" 2> /dev/null || return 0
    for _ in $(seq 1 100); do
        kill -0 "$pid" 2> /dev/null || return 0
        sleep 0.1
    done
    [ "$(owned_pid "$1" "$2" "$3")" = "$pid" ] && kill -9 "$pid" 2> /dev/null || true
}

cluster_dir() {  # DIR: the folder as up wrote it into slurm.conf (the daemons' command lines name it)
    local recorded=""
    [ -f "$1/slurm.conf" ] && recorded=$(sed -n 's|^StateSaveLocation=\(.*\)/state$|\1|p' "$1/slurm.conf" | head -n 1)
    if [ -n "$recorded" ]; then echo "$recorded"; else (cd "$1" && pwd); fi
}

stop_daemons() {  # DIR: its jobs cancelled, its daemons stopped (those that were started)
    local dir
    dir=$(cluster_dir "$1")
    if [ -f "$1/slurm.conf" ] && owned_pid "$1/slurmctld.pid" slurmctld "$dir" > /dev/null; then
        SLURM_CONF="$1/slurm.conf" scancel --full --quiet --user=root 2> /dev/null || true
    fi
    stop_pid_file "$1/slurmd.pid" slurmd "$dir"
    stop_pid_file "$1/slurmctld.pid" slurmctld "$dir"
    stop_pid_file "$1/munged.pid" munged "$dir"
}

down() {
    local dir=$1
    [ -d "$dir" ] || die "$dir is not a folder (give the DIR that up printed)"
    [ -f "$dir/munge.key" ] || die "$dir holds no cluster (no munge.key)"
    stop_daemons "$dir"
}

case "${2:-}" in -*) die "$USAGE" ;; esac  # an option where DIR goes (--help); a folder named -x is ./-x
case "${1:-}" in
    up) [ $# -le 2 ] || die "$USAGE"; up "${2:-}" ;;
    down) [ $# -eq 2 ] && [ -n "$2" ] || die "$USAGE"; down "$2" ;;
    *) die "$USAGE" ;;
esac
