#!/usr/bin/env bash
# A real single-node Slurm cluster (munged, slurmctld, slurmd, configured in a temporary
# folder and stopped after) bakes the finger and the Fox as job arrays with a dependent
# reduce (tools/slurm/sinew-farm submit) and inside an allocation (srun mode); each blob
# equals the local bake's byte for byte. Needs root and Debian's slurm-wlm and munge
# (tools/setup-debian.sh): without them, or when a daemon does not start, the test says
# exactly why and is skipped (exit 77); tests/farm.sh tests the sharded path without Slurm.
#   bash tests/slurm.sh BUILD_DIR SOURCE_DIR
set -uo pipefail
build=$1
src=$2
bake=$build/tools/sinew-bake
farm=$src/tools/slurm/sinew-farm
skip() {
    echo "slurm: SKIPPED: $*"
    exit 77
}
[ "$(id -u)" -eq 0 ] || skip "the daemons run as root in this test; running as uid $(id -u)"
for p in munged slurmctld slurmd sbatch; do
    command -v "$p" >/dev/null || skip "no $p (apt-get install slurm-wlm munge)"
done
tmp=$(mktemp -d)
stop() {
    for f in "$tmp/slurmd.pid" "$tmp/slurmctld.pid" "$tmp/munge/pid"; do
        [ -s "$f" ] && kill "$(cat "$f")" 2>/dev/null
    done
    sleep 1
    rm -rf "$tmp"
}
trap stop EXIT
mkdir -p "$tmp/munge" "$tmp/state" "$tmp/spool" "$tmp/log"
chmod 700 "$tmp/munge"
dd if=/dev/urandom of="$tmp/munge/munge.key" bs=1024 count=1 status=none
chmod 600 "$tmp/munge/munge.key"
munged --key-file="$tmp/munge/munge.key" --socket="$tmp/munge/sock" --pid-file="$tmp/munge/pid" \
    --log-file="$tmp/munge/log" --seed-file="$tmp/munge/seed" --force 2>"$tmp/munged.err" ||
    skip "munged does not start: $(cat "$tmp/munged.err" "$tmp/munge/log" 2>/dev/null | tail -3)"
host=$(hostname -s)
port=$((17000 + RANDOM % 2000)) # beside another run's cluster
cat >"$tmp/slurm.conf" <<CONF
ClusterName=sinewtest
SlurmctldHost=$host
SlurmUser=root
AuthType=auth/munge
AuthInfo=socket=$tmp/munge/sock
CredType=cred/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/log/slurmctld.log
SlurmdLogFile=$tmp/log/slurmd.log
SlurmctldPort=$port
SlurmdPort=$((port + 1))
ReturnToService=2
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
NodeName=$host CPUs=$(nproc) State=UNKNOWN
PartitionName=sinew Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$tmp/slurm.conf
slurmctld -f "$SLURM_CONF" 2>"$tmp/ctld.err" ||
    skip "slurmctld does not start: $(tail -3 "$tmp/ctld.err" "$tmp/log/slurmctld.log" 2>/dev/null)"
slurmd -f "$SLURM_CONF" 2>"$tmp/slurmd.err" ||
    skip "slurmd does not start: $(tail -3 "$tmp/slurmd.err" "$tmp/log/slurmd.log" 2>/dev/null)"
for _ in $(seq 30); do
    sinfo -h -o %t 2>/dev/null | grep -q idle && break
    sleep 1
done
sinfo -h -o %t 2>/dev/null | grep -q idle ||
    skip "the node never came up: $(sinfo 2>&1 | tail -2; tail -3 "$tmp/log/slurmd.log")"

fails=0
fail() {
    echo "FAIL $*" >&2
    fails=$((fails + 1))
}
# NAME N BAKE ARGS: the local bake, then the farm's submit mode, then its srun mode
check() {
    local name=$1 n=$2
    shift 2
    "$bake" "$@" --out "$tmp/$name-local.blob" >/dev/null 2>&1 || fail "$name: local bake"
    local id
    id=$(SINEW_BAKE=$bake "$farm" submit -n "$n" --cache "$tmp/$name-c1" \
        --out "$tmp/$name-submit.blob" -- "$@") || fail "$name: submit"
    for _ in $(seq 1200); do
        squeue -h 2>/dev/null | grep -q . || break
        sleep 1
    done
    scontrol show job "$id" 2>/dev/null | grep -q "JobState=COMPLETED" ||
        fail "$name: the reduce job $id: $(scontrol show job "$id" | grep -o 'JobState=[A-Z]*')"
    cmp -s "$tmp/$name-submit.blob" "$tmp/$name-local.blob" || fail "$name: submit's blob differs"
    local m=$((n < $(nproc) ? n : $(nproc))) # an allocation of this one node's cores
    salloc -n "$m" env SINEW_BAKE="$bake" "$farm" srun -n "$m" --cache "$tmp/$name-c2" \
        --out "$tmp/$name-srun.blob" -- "$@" >/dev/null 2>"$tmp/$name-srun.log" ||
        fail "$name: srun mode: $(tail -3 "$tmp/$name-srun.log")"
    cmp -s "$tmp/$name-srun.blob" "$tmp/$name-local.blob" || fail "$name: srun's blob differs"
}
check finger 3 --scene finger --tets 2000 --threads 1
check finger-adaptive 2 --scene finger --tets 2000 --threads 1 --adaptive 2
fox=$src/../shared/data/gltf-fox/Fox.glb
if [ -f "$fox" ]; then
    check fox 2 "$fox" --tets 2000 --threads 1 --train-clips Survey,Walk --heldout-clips Run
else
    echo "slurm: the Fox ($fox) is absent: only the finger"
fi
[ "$fails" -eq 0 ] && echo "slurm: every blob equals the local bake's"
exit $((fails > 0))
