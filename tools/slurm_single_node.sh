#!/usr/bin/env bash
# A progressive render on a real Slurm: a single-node cluster on this
# machine (Debian's slurm-wlm and munge), a job array that renders pass
# ranges as partial renders, an `afterok` job that merges them, and a check
# that the merged image is byte for byte the one-process render.
#
# usage (as root, on Debian or Ubuntu): tools/slurm_single_node.sh [PASSES] [TASKS]
#   (default 24 passes in 4 array tasks). Installs slurm-wlm and munge if
#   missing (apt-get). Run by hand, not in CI; notes/distributed.md has the
#   recipe it proves and a transcript.
set -euo pipefail
cd "$(dirname "$0")/.."
passes=${1:-24}
tasks=${2:-4}
work=${WORK:-/tmp/photonmap-slurm}
bin=$PWD/target/release/photonmap

if ! command -v slurmctld >/dev/null; then
  apt-get update && apt-get install -y --no-install-recommends slurm-wlm munge
fi
cargo build --release --bin photonmap -q
rm -rf "$work" && mkdir -p "$work"/{parts,spool,state,log}

# munge: a key, the daemon.
if [ ! -s /etc/munge/munge.key ]; then
  dd if=/dev/urandom bs=1 count=1024 of=/etc/munge/munge.key 2>/dev/null
fi
chown munge:munge /etc/munge/munge.key && chmod 400 /etc/munge/munge.key
mkdir -p /run/munge && chown munge:munge /run/munge
pgrep -x munged >/dev/null || su -s /bin/sh munge -c /usr/sbin/munged

# slurm: one node, this machine, all its cores.
host=$(hostname -s)
cpus=$(nproc)
mem=$(awk '/MemTotal/ { print int($2 / 1024) - 512 }' /proc/meminfo)
cat >/etc/slurm/slurm.conf <<EOF
ClusterName=photonmap
SlurmctldHost=$host
SlurmUser=root
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldLogFile=$work/log/slurmctld.log
SlurmdLogFile=$work/log/slurmd.log
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
NodeName=$host CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=render Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
pkill -x slurmctld || true
pkill -x slurmd || true
sleep 1
/usr/sbin/slurmctld -i
/usr/sbin/slurmd
for _ in $(seq 30); do
  sinfo -h -o %T 2>/dev/null | grep -qE 'idle|mixed' && break
  sleep 1
done
sinfo

# The render: the same flags for every job; only the pass range differs.
flags="--width 200 --height 200 --photons 1e5 --quiet"
per=$(( (passes + tasks - 1) / tasks ))
cat >"$work/render.sbatch" <<EOF
#!/bin/bash
#SBATCH --job-name=photonmap-part
#SBATCH --cpus-per-task=1
#SBATCH --output=$work/log/part-%a.out
a=\$(( SLURM_ARRAY_TASK_ID * $per ))
b=\$(( a + $per > $passes ? $passes : a + $per ))
exec $bin $flags --threads 1 --pass-range \$a..\$b --partial $work/parts/part-\$SLURM_ARRAY_TASK_ID.exr
EOF
cat >"$work/merge.sbatch" <<EOF
#!/bin/bash
#SBATCH --job-name=photonmap-merge
#SBATCH --output=$work/log/merge.out
exec $bin merge $work/parts/part-*.exr -o $work/merged.exr -o $work/merged.png --partial $work/all.exr
EOF
start=$(date +%s.%N)
array=$(sbatch --parsable --array=0-$((tasks - 1)) "$work/render.sbatch")
merge=$(sbatch --parsable --dependency=afterok:$array "$work/merge.sbatch")
echo "submitted array $array ($tasks tasks of $per passes), merge $merge (afterok)"
while squeue -h -j "$array,$merge" 2>/dev/null | grep -q .; do sleep 1; done
end=$(date +%s.%N)
sacct -j "$array,$merge" -X -o JobID,JobName,State,Elapsed 2>/dev/null || true
cat "$work/log/merge.out"
echo "cluster wall time: $(echo "$end - $start" | bc) s"

# The same passes in one process.
t0=$(date +%s.%N)
$bin $flags --threads "$cpus" --passes "$passes" "$work/one.exr" -o "$work/one.png"
t1=$(date +%s.%N)
echo "one process ($cpus threads): $(echo "$t1 - $t0" | bc) s"
$bin info "$work/all.exr" | sed -n '1,30p'
cmp "$work/merged.png" "$work/one.png" && echo "PNG: identical"
$bin compare "$work/merged.exr" "$work/one.exr" | sed -n '1,3p'
