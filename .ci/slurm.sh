#!/usr/bin/env bash
# A real one-node SLURM cluster on this machine: munge and the two daemons
# started here, `gi-studio farm slurm`'s array job of four shards and its
# merge job submitted, waited for, the merge compared with the one-process
# render, the daemons stopped. Fails, saying why, if any of it cannot run.
# Usage: .ci/slurm.sh path/to/gi-studio
set -euo pipefail
bin="$(realpath "$1")"
root="$(mktemp -d)"
export SLURM_CONF="$root/slurm.conf"
fail() { echo "slurm: $*" >&2; for log in "$root"/log/*.log; do [ -f "$log" ] && tail -n 20 "$log" >&2; done; exit 1; }
stop() {
    for pid in "$root"/run/slurmd.pid "$root"/run/slurmctld.pid; do [ -f "$pid" ] && kill "$(cat "$pid")" 2>/dev/null || true; done
    [ -n "${munge_pid:-}" ] && kill "$munge_pid" 2>/dev/null || true
    sleep 1
    rm -rf "$root"
}
trap stop EXIT

mkdir -p "$root"/{state,spool,log,run}
host="$(hostname -s)"
cat > "$SLURM_CONF" <<CONF
ClusterName=ci
SlurmctldHost=$host
AuthType=auth/munge
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
SlurmctldPidFile=$root/run/slurmctld.pid
SlurmdPidFile=$root/run/slurmd.pid
SlurmdSpoolDir=$root/spool
StateSaveLocation=$root/state
SlurmctldLogFile=$root/log/slurmctld.log
SlurmdLogFile=$root/log/slurmd.log
SlurmUser=root
SlurmdUser=root
MpiDefault=none
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
NodeName=$host CPUs=$(nproc) State=UNKNOWN
PartitionName=ci Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF

# munge: a key of its own if the package made none, its socket in /run/munge
[ -s /etc/munge/munge.key ] || { dd if=/dev/urandom of=/etc/munge/munge.key bs=1 count=1024 2>/dev/null; chown munge:munge /etc/munge/munge.key; chmod 400 /etc/munge/munge.key; }
mkdir -p /run/munge && chown munge:munge /run/munge
su -s /bin/sh munge -c "/usr/sbin/munged --force --pid-file=/run/munge/ci-munged.pid" || fail "munged did not start"
munge_pid="$(cat /run/munge/ci-munged.pid)"
munge -n | unmunge >/dev/null || fail "munge cannot encode and decode a credential"
slurmctld -f "$SLURM_CONF" || fail "slurmctld did not start"
slurmd -f "$SLURM_CONF" || fail "slurmd did not start"
for _ in $(seq 30); do sinfo -h -o %T 2>/dev/null | grep -q idle && break; sleep 1; done
sinfo -h -o %T | grep -q idle || fail "the node did not come up"

work="$root/work"
mkdir -p "$work"
scene="$(pwd)/assets/scenes/cornell.ron"
flags=(--algo path --spp 16 --width 64 --height 48)
"$bin" farm slurm "$scene" --shards 4 --cpus 1 --out "$work/farm" -- "${flags[@]}"
bash "$work/farm/submit.sh"
for _ in $(seq 300); do [ -z "$(squeue -h)" ] && break; sleep 1; done
[ -z "$(squeue -h)" ] || fail "the jobs did not finish within 5 minutes: $(squeue)"
[ -f "$work/farm/merged.exr" ] || fail "no merged image: $(cat "$work"/farm/logs/*.log)"
cat "$work/farm/logs/merge.log"
"$bin" render "$scene" "${flags[@]}" -o "$work/whole.exr"
"$bin" compare "$work/farm/merged.exr" "$work/whole.exr" --max-rel-mse 1e-9
echo "slurm: four shards on a real SLURM merged to the one-process render"
