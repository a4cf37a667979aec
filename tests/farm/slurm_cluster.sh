#!/usr/bin/env bash
# A single-node Slurm cluster for the farm test, in a folder of its own: munged, slurmctld and
# slurmd started here and stopped on exit. Run inside a network namespace with only loopback
# (see slurm_farm_test.sh), so nothing it starts can listen beyond this machine.
#
# usage: source slurm_cluster.sh DIR   then   start_cluster; ...; (stop_cluster runs on exit)
# Exports SLURM_CONF for sbatch, squeue and sinfo.

cluster_dir="$1"
missing=()
for tool in munged mungekey slurmctld slurmd sbatch squeue sinfo scontrol; do
  command -v "$tool" > /dev/null || missing+=("$tool")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "farm test cannot run: ${missing[*]} not installed (packages munge, slurmctld, slurmd," \
       "slurm-client; tools/scripts/install_deps.sh installs them)" >&2
  exit 1
fi

cluster_pids=()
stop_cluster() {
  for pid in "${cluster_pids[@]}"; do kill "$pid" 2> /dev/null || true; done
  for pid in "${cluster_pids[@]}"; do wait "$pid" 2> /dev/null || true; done
}
trap stop_cluster EXIT

start_cluster() {
  local node cpus memory_mib
  node="$(hostname -s)"
  cpus="$(nproc)"
  memory_mib=$(($(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 / 2))
  mkdir -p "$cluster_dir"/{munge,state,spool,log}
  chmod 700 "$cluster_dir/munge"
  mungekey --create --keyfile="$cluster_dir/munge/munge.key" --force
  munged --foreground --force --socket="$cluster_dir/munge/munge.socket" \
    --key-file="$cluster_dir/munge/munge.key" --pid-file="$cluster_dir/munge/munged.pid" \
    --log-file="$cluster_dir/log/munged.log" --seed-file="$cluster_dir/munge/munged.seed" &
  cluster_pids+=($!)
  cat > "$cluster_dir/slurm.conf" <<CONF
ClusterName=siviflow-test
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=16817
SlurmdPort=16818
SlurmUser=$(id -un)
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$cluster_dir/munge/munge.socket
CredType=cred/munge
StateSaveLocation=$cluster_dir/state
SlurmdSpoolDir=$cluster_dir/spool
SlurmctldPidFile=$cluster_dir/slurmctld.pid
SlurmdPidFile=$cluster_dir/slurmd.pid
SlurmctldLogFile=$cluster_dir/log/slurmctld.log
SlurmdLogFile=$cluster_dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
SlurmctldTimeout=30
SlurmdTimeout=30
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$memory_mib State=UNKNOWN
PartitionName=farm Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF="$cluster_dir/slurm.conf"
  slurmctld -D -i -f "$SLURM_CONF" &
  cluster_pids+=($!)
  slurmd -D -f "$SLURM_CONF" -N "$node" &
  cluster_pids+=($!)
  for _ in $(seq 120); do
    if sinfo -h -o %T 2> /dev/null | grep -qx idle; then return 0; fi
    sleep 0.5
  done
  echo "farm test: the Slurm node did not come up; logs in $cluster_dir/log" >&2
  tail -n 20 "$cluster_dir"/log/*.log >&2
  return 1
}
