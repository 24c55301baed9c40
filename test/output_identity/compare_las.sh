#!/usr/bin/env bash
# compare_las.sh OLD_TOOLS_DIR NEW_TOOLS_DIR [DATA_DIR]
#
# The LAS cases compare_tools.sh leaves out (its old tools could not read LAS), for two builds that
# both can: every LAS file of DATA_DIR (default: ../shared/data beside the repository; LAZ files
# are refused, and the refusals compared) through normals, curvature and info into .las, .ply and
# .pcd, in memory and out of core (-memory), plus clouds and meshes written as new LAS files and
# batch mode over a folder. Every output file, stdout, stderr (timings and paths removed) and the
# exit status are compared. Prints "same <case>" or "DIFFERENT <case>: why", then the counts; exit
# status 1 if any case differs.
set -uo pipefail
if [[ $# -lt 2 || $# -gt 3 ]]; then
  echo "usage: $0 OLD_TOOLS_DIR NEW_TOOLS_DIR [DATA_DIR]" >&2
  exit 2
fi
REPO=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
OLD=$(cd "$1" && pwd)
NEW=$(cd "$2" && pwd)
DATA=$(cd "${3:-$REPO/../shared/data}" && pwd)
S=$(mktemp -d)
trap 'rm -rf "$S"' EXIT
same=0
diff=0
run_case() {  # name, tool, args... (OUT/ in args is the output folder)
  local name=$1 tool=$2
  shift 2
  for set in old new; do
    local dir=$OLD
    [[ $set == new ]] && dir=$NEW
    mkdir -p "$S/$set/$name"
    local args=("${@//OUT\//$S/$set/$name/}")
    (cd "$S/$set/$name" && "$dir/$tool" "${args[@]}" >stdout 2>stderr; echo $? >status)
    sed -i -E "s#$S/$set#SCRATCH#g; s/[0-9]+(\.[0-9]+)? ?(ms|s)\b/T/g; s/[0-9.]+ ?[kMG]i?B (peak|resident)/M/g" \
      "$S/$set/$name/stdout" "$S/$set/$name/stderr"
  done
  local why="" f
  for f in $(cd "$S/old/$name" && ls -A) ; do
    [[ -e $S/new/$name/$f ]] || { why+=" $f missing in new"; continue; }
    diff -rq "$S/old/$name/$f" "$S/new/$name/$f" >/dev/null || why+=" $f differs"
  done
  for f in $(cd "$S/new/$name" && ls -A); do
    [[ -e $S/old/$name/$f ]] || why+=" $f only in new"
  done
  if [[ -z $why ]]; then
    same=$((same + 1))
    echo "same $name (exit $(cat "$S/old/$name/status"))"
  else
    diff=$((diff + 1))
    echo "DIFFERENT $name:$why"
  fi
}
LAS=("$DATA"/las/*.las "$DATA"/las/formats/*.las)
for f in "${LAS[@]}"; do
  b=$(basename "$f" .las)
  run_case "info_$b" pcl_ddg_info "$f"
  run_case "normals_las_$b" pcl_ddg_normals "$f" OUT/out.las -k 16
  run_case "normals_double_las_$b" pcl_ddg_normals "$f" OUT/out.las -k 16 -precision double
  run_case "normals_ply_$b" pcl_ddg_normals "$f" OUT/out.ply -k 16
  run_case "normals_pcd_$b" pcl_ddg_normals "$f" OUT/out.pcd -k 16
  run_case "normals_memory_las_$b" pcl_ddg_normals "$f" OUT/out.las -k 16 -memory 64M
  run_case "normals_radius_las_$b" pcl_ddg_normals "$f" OUT/out.las -radius 1
  run_case "normals_radius_memory_las_$b" pcl_ddg_normals "$f" OUT/out.las -radius 1 -memory 64M
  run_case "normals_radius_pcd_$b" pcl_ddg_normals "$f" OUT/out.pcd -radius 1
  run_case "curvature_las_$b" pcl_ddg_curvature "$f" OUT/out.las -method quadric
  run_case "curvature_memory_las_$b" pcl_ddg_curvature "$f" OUT/out.las -method quadric -memory 64M
done
for f in "$DATA"/las/simple.laz "$DATA"/las/laz/*.laz; do
  b=$(basename "$f" .laz)
  run_case "laz_normals_$b" pcl_ddg_normals "$f" OUT/out.las
  run_case "laz_info_$b" pcl_ddg_info "$f"
done
# Clouds and meshes written as new LAS files (LAS 1.4 format 6/7, scale and offset chosen).
for f in clouds/bun0.pcd clouds/milk.pcd clouds/rs1.pcd clouds/terrain_CSite1_red2-utm.pcd \
  meshes/bun_zipper.ply meshes/bunny.off; do
  b=$(basename "$f")
  run_case "to_las_normals_$b" pcl_ddg_normals "$DATA/$f" OUT/out.las
  run_case "to_las_curvature_$b" pcl_ddg_curvature "$DATA/$f" OUT/out.las
done
run_case "to_las_memory_bun0" pcl_ddg_normals "$DATA/clouds/bun0.pcd" OUT/out.las -memory 64M
run_case "to_las_smooth_bunny" pcl_ddg_smooth "$DATA/meshes/bunny.off" OUT/out.las
# LAS written back from a written LAS (the layout round trip), and batch mode over a folder.
run_case "batch_formats" pcl_ddg_normals -input_dir "$DATA/las/formats" -output_dir OUT/o -radius 1
run_case "batch_las" pcl_ddg_curvature -input_dir "$DATA/las" -output_dir OUT/o -method quadric
echo "$same same, $diff different"
[[ $diff == 0 ]]
