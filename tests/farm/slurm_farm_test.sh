#!/usr/bin/env bash
# The farm tier: a single-node Slurm cluster from Debian's packages (munge, slurmctld, slurmd),
# started in a network namespace that has only loopback and a link to nowhere (so nothing it
# starts can be reached from beyond this machine), runs tools/farm/submit_slurm.sh: a 4-task
# array over 24 frames, into a folder that does not exist yet (the scripts create it), and the
# verify job after it. The frames must be bit-identical to one local
# capture of the same range, and verify must find all 24 complete. Fails, saying why, when a
# package or the namespace is missing.
#
# usage: slurm_farm_test.sh SIVIFLOW_BINARY SOURCE_DIR WORK_DIR
set -euo pipefail
binary="$1" source_dir="$2" work="$3"

if [ "${SIVIFLOW_FARM_NAMESPACE:-}" != 1 ]; then
  namespace=(unshare --net)
  [ "$(id -u)" -eq 0 ] || namespace=(unshare --net --map-root-user)
  if ! "${namespace[@]}" true 2> /dev/null; then
    echo "farm test cannot run: '${namespace[*]}' is refused here (it needs root or user" \
         "namespaces, to keep the cluster off the network)" >&2
    exit 1
  fi
  SIVIFLOW_FARM_NAMESPACE=1 exec "${namespace[@]}" bash "$0" "$@"
fi

# The namespace: loopback, and a veth pair with an address, which Slurm's address lookup
# (getaddrinfo with AI_ADDRCONFIG) needs to find IPv4 configured; the pair leads nowhere.
ip link set lo up
ip link add siviflow0 type veth peer name siviflow1
ip addr add 10.254.254.1/30 dev siviflow0
ip link set siviflow0 up
ip link set siviflow1 up

rm -rf "$work"
mkdir -p "$work/local"  # and not $work/farm: submit_slurm.sh and the tasks create it
farm="$source_dir/tools/farm"
export SIVIFLOW="$binary"
capture_options=(--size 64x36 --aov depth)

# Refusals that need no cluster.
for bad in "0 24 0" "0 24 5"; do
  # shellcheck disable=SC2086
  if message=$(bash "$farm/submit_slurm.sh" $bad "$work/farm" 2>&1); then
    echo "FAIL: submit_slurm.sh accepted chunking '$bad'" >&2
    exit 1
  fi
  echo "refused '$bad': $message"
done

source "$source_dir/tests/farm/slurm_cluster.sh" "$work/cluster"
start_cluster

"$binary" capture --range 0:24 "${capture_options[@]}" --out "$work/local" > /dev/null
bash "$farm/submit_slurm.sh" 0 24 6 "$work/farm" "${capture_options[@]}"
for _ in $(seq 600); do
  [ -z "$(squeue -h)" ] && break
  sleep 1
done
if [ -n "$(squeue -h)" ]; then
  echo "FAIL: jobs still queued after 10 minutes:" >&2
  squeue >&2
  exit 1
fi

status=0
verify_log=$(cat "$work/farm/slurm-logs"/verify-*.log 2> /dev/null || true)
echo "verify job: $verify_log"
if ! grep -q "frames 0..23: 24 of 24 complete$" <<< "$verify_log"; then
  echo "FAIL: the verify job did not find 24 complete frames" >&2
  tail -n 5 "$work/farm/slurm-logs"/*.log >&2 || true
  status=1
fi
tasks=$(ls "$work/farm/slurm-logs"/capture-*.log 2> /dev/null | wc -l)
[ "$tasks" -eq 4 ] || { echo "FAIL: $tasks array task logs, not 4" >&2; status=1; }
for frame in $(seq -f "%05g" 0 23); do
  if ! cmp -s "$work/local/frame_$frame.exr" "$work/farm/frame_$frame.exr"; then
    echo "FAIL: frame_$frame.exr of the farm differs from the local capture's" >&2
    status=1
  fi
done
[ "$status" -eq 0 ] && echo "24 frames from 4 array tasks bit-identical to the local capture"
exit "$status"
