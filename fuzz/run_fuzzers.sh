#!/usr/bin/env bash
# Runs every libFuzzer target of a sanitize build for a while, each seeded with the small files in
# fuzz/seeds/<format> and the shared scans of that format (read in place, never copied here).
#   fuzz/run_fuzzers.sh BUILD_DIR SECONDS_PER_TARGET [TARGET ...]
# New corpus entries stay in BUILD_DIR/fuzz/corpus/<target>; a finding is written to
# BUILD_DIR/fuzz/findings/ and makes this script fail. Inputs may cost at most 256 MiB in one
# allocation (a small file that asks for more is a lying count the loader should have refused).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=$(cd "$1" && pwd)
seconds=$2
shift 2
targets=("$@")
((${#targets[@]})) || targets=(ply off obj stl vtk pcd las laz mesh)
# The shared scans, where the tests look for them too (test/CMakeLists.txt).
shared=${PCL_DDG_SHARED_DATA:-}
for candidate in "$here/../../shared/data" /work/shared/data; do
  [ -z "$shared" ] && [ -f "$candidate/CATALOG.md" ] && shared=$candidate
done

# One target's run; its summary goes to BUILD_DIR/fuzz/<target>.summary, printed when it ends.
fuzz_target() {
  local target=$1 corpus=$build/fuzz/corpus/$1 seeds=$build/fuzz/seeds/$1
  local findings=$build/fuzz/findings/$1 summary=$build/fuzz/$1.summary dict=()
  mkdir -p "$corpus" "$seeds" "$findings"
  rm -f "$seeds"/*
  if [ -d "$here/seeds/$target" ]; then cp "$here/seeds/$target"/* "$seeds"/; fi
  if [ -n "$shared" ]; then
    find "$shared" -type f -name "*.$target" -exec ln -sf {} "$seeds"/ \;
  fi
  [ -f "$here/$target.dict" ] && dict=(-dict="$here/$target.dict")
  echo "== fuzz_$target for ${seconds}s" > "$summary"
  if ! "$build/fuzz/fuzz_$target" "$corpus" "$seeds" "${dict[@]}" -max_total_time="$seconds" \
      -max_len=16384 -timeout=20 -rss_limit_mb=2048 -malloc_limit_mb=256 -print_final_stats=1 \
      -artifact_prefix="$findings/" 2>"$build/fuzz/$target.log"; then
    echo "fuzz_$target: FINDING (see $findings and $build/fuzz/$target.log)" >> "$summary"
    grep -E "ERROR|SUMMARY|runtime error" "$build/fuzz/$target.log" | head -5 >> "$summary" || true
    return 1
  fi
  grep -E "stat::number_of_executed_units|cov:" "$build/fuzz/$target.log" | tail -2 >> "$summary" || true
}

# The targets run side by side, one per core: each is single-threaded.
jobs=${PCL_DDG_FUZZ_JOBS:-$(nproc)}
[[ $jobs =~ ^[1-9][0-9]*$ ]] || { echo "PCL_DDG_FUZZ_JOBS must be a positive number" >&2; exit 2; }
for target in "${targets[@]}"; do rm -f "$build/fuzz/$target.summary"; done
status=0
running=0
for target in "${targets[@]}"; do
  if ((running >= jobs)); then
    wait -n || status=1
    running=$((running - 1))
  fi
  fuzz_target "$target" &
  running=$((running + 1))
done
while ((running > 0)); do
  wait -n || status=1
  running=$((running - 1))
done
for target in "${targets[@]}"; do
  cat "$build/fuzz/$target.summary" 2>/dev/null || { echo "fuzz_$target: no summary"; status=1; }
done
exit $status
