#!/usr/bin/env bash
# A one-node Slurm on this machine, to run the cluster recipes of examples/cluster/ for real:
# installs Debian's slurm-wlm and munge, writes /etc/slurm/slurm.conf for this host (all its cores
# and 85 % of its memory, one partition "local", no cgroups, no accounting) unless one is there,
# and starts munged, slurmctld and slurmd unless they run. Needs root. Then, for example:
#   sbatch --array=0-3 --cpus-per-task=1 --mem=1G --export=ALL,SAMPLE=sph,VOXEL=0.028125 examples/cluster/slurm_rasterize.sh
#   bash scripts/local_slurm.sh stop      stops the three daemons (the configuration stays)
set -euo pipefail
if [ "${1:-}" = stop ]; then
  for d in slurmd slurmctld munged; do pkill -x "$d" || true; done
  exit 0
fi
[ "$(id -u)" = 0 ] || { echo "local_slurm.sh: run as root (it installs packages and starts daemons)" >&2; exit 1; }
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge >/dev/null
fi
host=$(hostname)
mkdir -p /var/lib/slurm/slurmd /var/lib/slurm/slurmctld /var/log/slurm /run/munge
if [ ! -f /etc/slurm/slurm.conf ]; then
  mem_mb=$(awk '/MemTotal/ { printf "%d", $2 / 1024 * 0.85 }' /proc/meminfo)
  cat > /etc/slurm/slurm.conf <<EOF
# Written by angiosynth's scripts/local_slurm.sh: one node, no cgroups, no accounting.
ClusterName=local
SlurmctldHost=$host
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
ReturnToService=2
SlurmUser=root
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
SlurmdSpoolDir=/var/lib/slurm/slurmd
StateSaveLocation=/var/lib/slurm/slurmctld
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
NodeName=$host CPUs=$(nproc) RealMemory=$mem_mb State=UNKNOWN
PartitionName=local Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
fi
[ -f /etc/munge/munge.key ] || mungekey --create >/dev/null 2>&1 || dd if=/dev/urandom of=/etc/munge/munge.key bs=1 count=128 2>/dev/null
chown -R munge:munge /etc/munge /run/munge /var/log/munge /var/lib/munge 2>/dev/null || true
chmod 400 /etc/munge/munge.key
pgrep -x munged >/dev/null || munged --force 2>/dev/null
pgrep -x slurmctld >/dev/null || slurmctld
pgrep -x slurmd >/dev/null || slurmd
for _ in $(seq 1 30); do
  sinfo -h -o %T 2>/dev/null | grep -q idle && { sinfo; exit 0; }
  sleep 1
done
echo "local_slurm.sh: the node did not come up; see /var/log/slurm/" >&2
exit 1
