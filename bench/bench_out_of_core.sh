#!/usr/bin/env bash
# A cloud three times larger than the machine's memory, fitted by `pcl_ddg_normals -memory`, and
# compared byte for byte with the in-memory run. The "machine" is a cgroup (v1 memory controller,
# root needed) whose limit counts the page cache too, so the file cannot sit in memory either; the
# in-memory run for the comparison runs outside it.
#   bash bench/bench_out_of_core.sh [build folder] [machine memory in MiB] [scratch folder]
set -euo pipefail
build=${1:-build}
machine_mib=${2:-400}
scratch=${3:-/tmp/pcl_ddg_bench_out_of_core}
budget_mib=$((machine_mib / 2))
points=$((3 * machine_mib * 1024 * 1024 / 12))  # float x y z: 12 bytes a point
cgroup=/sys/fs/cgroup/memory/pcl_ddg_bench_out_of_core
normals="$build/tools/pcl_ddg_normals"

[ -d /sys/fs/cgroup/memory ] || { echo "needs the cgroup v1 memory controller" >&2; exit 1; }
mkdir -p "$scratch" "$cgroup"
trap 'rm -rf "$scratch"; rmdir "$cgroup" 2>/dev/null || true' EXIT
echo "writing $points points sampled on igea.ply ($((points * 12 / 1048576)) MiB)"
"$build/bench/bench_scale" --write-cloud="$points:$scratch/cloud.ply"

echo $((machine_mib * 1024 * 1024)) > "$cgroup/memory.limit_in_bytes"
echo 0 > "$cgroup/memory.max_usage_in_bytes"
sync && echo 3 > /proc/sys/vm/drop_caches  # the file is read from disk, as on a real machine
start=$(date +%s.%N)
(echo $BASHPID > "$cgroup/cgroup.procs" &&
  exec "$normals" "$scratch/cloud.ply" "$scratch/tiled.ply" -k 16 -memory "${budget_mib}M")
tiled_s=$(echo "$(date +%s.%N) - $start" | bc)
tiled_peak=$(cat "$cgroup/memory.max_usage_in_bytes")
failures=$(cat "$cgroup/memory.failcnt")

start=$(date +%s.%N)
/usr/bin/time -f "%M" -o "$scratch/in_memory_peak" \
  "$normals" "$scratch/cloud.ply" "$scratch/in_memory.ply" -k 16
memory_s=$(echo "$(date +%s.%N) - $start" | bc)

identical=no
cmp -s "$scratch/tiled.ply" "$scratch/in_memory.ply" && identical=yes
echo
echo "| run | machine | wall (s) | peak memory (MiB) |"
echo "|---|---|---|---|"
printf "| -memory %sM, %s points (%s MiB, 3x the machine) | cgroup of %s MiB | %.1f | %d (page cache included; %s times at the limit) |\n" \
  "$budget_mib" "$points" "$((points * 12 / 1048576))" "$machine_mib" "$tiled_s" \
  $((tiled_peak / 1048576)) "$failures"
printf "| in memory | the whole VM | %.1f | %d (resident) |\n" "$memory_s" \
  $(($(cat "$scratch/in_memory_peak") / 1024))
echo "outputs byte-identical: $identical"
[ "$identical" = yes ]
