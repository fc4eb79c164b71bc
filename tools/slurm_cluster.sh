#!/usr/bin/env bash
# A real one-node Slurm cluster on this machine, and a sweep through it: the
# check that `spatter sweep --slurm` writes a job array Slurm runs, and that
# the array's cells give the figures a local sweep gives.
#
#   tools/slurm_cluster.sh [SPATTER]      (as root; SPATTER defaults to target/release/spatter)
#
# It installs Debian's slurm-wlm and munge when missing, makes a munge key,
# starts munged, slurmctld and slurmd with a generated slurm.conf (one node,
# this machine's cores, no accounting, no cgroups) in a scratch folder, runs a
# 2-cell sweep of the README's 2D line melt (30 us a run) locally and as a job
# array submitted with `sbatch --wait`, runs `sweep collect` on the array and
# compares every cell's figures with the local sweep's (exit 1 on a
# difference), then stops the daemons. tests/sweep.rs runs it when Slurm is
# installed and the tests run as root. About 12 s.
#
# On a real cluster: `spatter sweep SCENE --vary ... --slurm --out DIR` writes
# DIR/sweep.slurm. Each array task runs `spatter sweep cell DIR i`, so DIR must
# be on a file system every node sees, and the spatter binary at the path the
# script names. Add what your site needs as #SBATCH lines with --slurm-arg
# (repeat it): the partition (--slurm-arg=--partition=gpu), a time limit
# (--slurm-arg=--time=02:00:00), the account; the script asks one GPU a task
# (--gpus=1) unless the sweep runs with --backend cpu, and Slurm's
# MaxArraySize (1001 by default) bounds the grid. Submit with
# `sbatch DIR/sweep.slurm`, then `spatter sweep collect DIR`.
set -euo pipefail
cd "$(dirname "$0")/.."
SPATTER="$(realpath "${1:-target/release/spatter}")"
[ -x "$SPATTER" ] || { echo "no spatter binary at $SPATTER (cargo build --release)"; exit 2; }
[ "$(id -u)" -eq 0 ] || { echo "run as root: the daemons run as root here"; exit 2; }

if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    echo "installing Debian's slurm-wlm and munge"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge >/dev/null
fi

STATE="$(mktemp -d /tmp/spatter_slurm.XXXXXX)"
mkdir -p "$STATE/ctld" "$STATE/d" /run/munge
NODE="$(hostname -s)"
CONF="$STATE/slurm.conf"
export SLURM_CONF="$CONF"

stop() {
    scontrol shutdown >/dev/null 2>&1 || true
    [ -f "$STATE/slurmd.pid" ] && kill "$(cat "$STATE/slurmd.pid")" 2>/dev/null || true
    [ -f "$STATE/munged.pid" ] && kill "$(cat "$STATE/munged.pid")" 2>/dev/null || true
}
trap stop EXIT

# munge: a key of its own for this cluster, the daemon on its own socket
dd if=/dev/urandom of="$STATE/munge.key" bs=1 count=1024 status=none
chmod 0400 "$STATE/munge.key"
SOCK="$STATE/munge.socket"
munged --force --key-file="$STATE/munge.key" --socket="$SOCK" \
    --pid-file="$STATE/munged.pid" --log-file="$STATE/munged.log" --seed-file="$STATE/munged.seed"

cat > "$CONF" <<CONF
ClusterName=spatter
SlurmctldHost=$NODE
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$SOCK
CredType=cred/munge
StateSaveLocation=$STATE/ctld
SlurmdSpoolDir=$STATE/d
SlurmctldPidFile=$STATE/slurmctld.pid
SlurmdPidFile=$STATE/slurmd.pid
SlurmctldLogFile=$STATE/slurmctld.log
SlurmdLogFile=$STATE/slurmd.log
SlurmctldPort=6817
SlurmdPort=6818
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
NodeName=$NODE CPUs=$(nproc) State=UNKNOWN
PartitionName=debug Nodes=$NODE Default=YES MaxTime=INFINITE State=UP
CONF

slurmctld -f "$CONF"
slurmd -f "$CONF"
for _ in $(seq 1 60); do
    sinfo -h -o %T 2>/dev/null | grep -q idle && break
    sleep 0.5
done
sinfo -h -o "%P %D %T" | grep -q idle || { echo "slurm did not come up"; tail -n 20 "$STATE"/*.log; exit 1; }
echo "slurm: $(sinfo -h -o '%P %D %T %c')"

SCENE="scenarios/pbf/line_melt_coarse_2d.toml"
ARGS=(--vary laser.power=1.0e6,2.0e6 --set run.end_time=3e-5 --backend cpu)
"$SPATTER" sweep "$SCENE" "${ARGS[@]}" --jobs 2 --out "$STATE/local" >/dev/null
"$SPATTER" sweep "$SCENE" "${ARGS[@]}" --slurm --out "$STATE/array" \
    --slurm-arg=--time=00:10:00
sbatch --wait "$STATE/array/sweep.slurm"
"$SPATTER" sweep collect "$STATE/array" >/dev/null
if ! diff "$STATE/local/sweep.csv" "$STATE/array/sweep.csv"; then
    echo "slurm: the array's figures differ from the local sweep's ($STATE)"
    exit 1
fi
echo "slurm: $(($(wc -l < "$STATE/array/sweep.csv") - 1)) cells through sbatch, figures equal to the local sweep's"
stop
trap - EXIT
# the daemons write their state as they go down: wait for them, then tidy up
for _ in $(seq 1 40); do
    pgrep -f "$CONF" >/dev/null || pgrep -f "$SOCK" >/dev/null || break
    sleep 0.25
done
rm -rf "$STATE" 2>/dev/null || { sleep 1; rm -rf "$STATE" 2>/dev/null || true; }
sleep 0.5
rm -rf "$STATE" 2>/dev/null || true
