#!/usr/bin/env bash
# The mutation check: plants each mutant of test/mutation/mutants.txt (a small change to one line of
# the library) in a copy of the tree, rebuilds only the test targets the mutant names, runs them,
# and reports whether a test caught it (killed) or not (survived).
#
#   bash test/mutation/run_mutants.sh [options] [ID ...]
#
#   ID ...          run only these mutants (default: every mutant of the list)
#   -j N            build jobs (default: nproc)
#   --list FILE     the mutant list (default: test/mutation/mutants.txt)
#   --check         only check the list against the working tree (each `find` exactly once in its
#                   file, on one line; every test target exists in test/CMakeLists.txt); no build
#   --all-tests     run every listed test target of a mutant, not only up to the first that fails
#   --timeout S     per test program, per mutant (default: 4 x its unmutated time + 120 s)
#   --report FILE   also write the result table (Markdown) to FILE
#   --keep          keep the scratch folder (source copy, build, logs) and print where it is
#   --reuse DIR     use the scratch folder a --keep run left (its build is updated incrementally)
#   --in-place DIR  no copy: mutate the repository itself and rebuild DIR (a configured, built
#                   Release build of it, tests and tools ON) incrementally; each file is restored
#                   after its mutant, and DIR's targets are rebuilt unmutated at the end
#   --no-rebuild    with --in-place: DIR's mutated targets are left to the next build (whose
#                   sources are restored and newer) instead of rebuilt at the end (CI's last step:
#                   a mutant of a header the estimators include costs minutes of rebuilding)
#   --pick N        run N mutants chosen from the commit hash (git rev-parse HEAD) among the
#                   selected ones: each commit checks another pair, the same pair on every rerun
#
# How it runs:
#   1. The source tree (`git ls-files`: tracked and untracked-not-ignored files, with their
#      working-tree content as it is now, uncommitted edits included) is copied once into a scratch
#      folder (mktemp -d under $TMPDIR or /tmp).
#   2. It is configured once: Release, tests and tools ON (the tool tests count), benchmarks,
#      fuzzers, viewer and examples OFF; Ninja when installed, else Makefiles. Built once, whole.
#   3. Baseline: every test program the selected mutants name runs once unmutated. A test that
#      fails there is left out of the mutant runs (gtest negative filter) and reported, and the
#      script then exits non-zero whatever the mutants give.
#   4. Per mutant: the replacement is applied to the copy (the `find` text must occur exactly once
#      in the file, else the mutant is an ERROR of the list), the listed test targets are rebuilt
#      incrementally (a mutant that does not compile is an ERROR of the list, not a kill), the
#      test programs run in the order listed (cwd: the build's test folder, TMPDIR private to the
#      run), each with a timeout. A failing test, a crash or a timeout kills the mutant. The file
#      is then restored.
#   5. A table (id, file:line, description, result, seconds, what caught it) and the totals.
#
# A test is a test target of test/CMakeLists.txt, or pytest:PATH[::NAME] (a pytest file or case,
# from the repository root) for the Python module and the Dask runner: it rebuilds the module and
# the tools and runs pytest on the copy with the build's module, tools and the shared data.
#
# Exit status: 0 when every mutant was killed and the baseline passed; 1 when a mutant survived or
# is an ERROR, or the baseline had failures; 2 on a usage or setup error (configure or build of the
# unmutated tree failed).
#
# The list's format is described at the top of mutants.txt.
set -uo pipefail
shopt -u patsub_replacement 2>/dev/null || true  # bash 5.2: '&' in a replacement stays literal

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/../.." && pwd)
list=$here/mutants.txt
jobs=$(nproc 2>/dev/null || echo 2)
check_only=0
all_tests=0
in_place=""
rebuild_after=1
pick=0
timeout_override=""
report=""
keep=0
reuse=""
selected=()

usage() { sed -n '2,/^# How it runs:/p' "${BASH_SOURCE[0]}" | sed '$d; s/^# \{0,1\}//'; }
die() { echo "run_mutants: $*" >&2; exit 2; }

while (($#)); do
  case "$1" in
    -j) [[ $# -ge 2 ]] || die "-j needs a number"; jobs=$2; shift 2 ;;
    -j*) jobs=${1#-j}; shift ;;
    --list) [[ $# -ge 2 ]] || die "--list needs a file"; list=$2; shift 2 ;;
    --check) check_only=1; shift ;;
    --all-tests) all_tests=1; shift ;;
    --timeout) [[ $# -ge 2 ]] || die "--timeout needs seconds"; timeout_override=$2; shift 2 ;;
    --report) [[ $# -ge 2 ]] || die "--report needs a file"; report=$2; shift 2 ;;
    --keep) keep=1; shift ;;
    --reuse) [[ $# -ge 2 ]] || die "--reuse needs a folder"; reuse=$2; keep=1; shift 2 ;;
    --in-place) [[ $# -ge 2 ]] || die "--in-place needs a build folder"; in_place=$2; shift 2 ;;
    --no-rebuild) rebuild_after=0; shift ;;
    --pick) [[ $# -ge 2 && $2 =~ ^[1-9][0-9]*$ ]] || die "--pick needs a number"; pick=$2; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    -*) usage >&2; die "unknown option $1" ;;
    *) selected+=("$1"); shift ;;
  esac
done
[[ $jobs =~ ^[1-9][0-9]*$ ]] || die "-j takes a positive number, not '$jobs'"
[[ -z $timeout_override || $timeout_override =~ ^[1-9][0-9]*$ ]] || die "--timeout takes seconds"
[[ -f $list ]] || die "no mutant list at $list"
[[ -n $report ]] && report=$(realpath -m "$report")

# ---- the list ---------------------------------------------------------------------------------
ids=()
declare -A m_why m_file m_find m_replace m_tests m_filter m_has_find m_has_replace
list_errors=0
list_error() { echo "run_mutants: $list:$1: $2" >&2; list_errors=$((list_errors + 1)); }

parse_list() {
  local number=0 line id="" key value
  while IFS= read -r line || [[ -n $line ]]; do
    number=$((number + 1))
    line=${line%$'\r'}
    [[ -z $line || $line == \#* ]] && continue
    if [[ $line =~ ^\[([A-Za-z0-9_.-]+)\]\ (.+)$ ]]; then
      id=${BASH_REMATCH[1]}
      if [[ -n ${m_why[$id]+x} ]]; then list_error "$number" "mutant $id appears twice"; fi
      ids+=("$id")
      m_why[$id]=${BASH_REMATCH[2]}
      continue
    fi
    if [[ -z $id ]]; then list_error "$number" "text before the first [ID] line"; continue; fi
    if [[ $line =~ ^(file|find|replace|tests|filter):\ (.*)$ ]]; then
      key=${BASH_REMATCH[1]} value=${BASH_REMATCH[2]}
      case $key in
        file) m_file[$id]=$value ;;
        find) m_find[$id]=$value; m_has_find[$id]=1 ;;
        replace) m_replace[$id]=$value; m_has_replace[$id]=1 ;;
        tests) m_tests[$id]=$value ;;
        filter) m_filter[$id]=$value ;;
      esac
    else
      list_error "$number" "not a [ID] line, a 'key: value' line (file, find, replace, tests, filter), a comment or blank: $line"
    fi
  done < "$list"
  for id in "${ids[@]}"; do
    [[ -n ${m_file[$id]:-} ]] || list_error 0 "$id has no file"
    [[ -n ${m_find[$id]:-} ]] || list_error 0 "$id has no (or an empty) find"
    [[ -n ${m_has_replace[$id]:-} ]] || list_error 0 "$id has no replace"
    [[ -n ${m_tests[$id]:-} ]] || list_error 0 "$id has no tests"
    [[ ${m_find[$id]:-} != "${m_replace[$id]:-}" ]] || list_error 0 "$id: replace equals find"
  done
}
parse_list
((list_errors == 0)) || die "$list_errors error(s) in the mutant list"

if ((${#selected[@]})); then
  for id in "${selected[@]}"; do
    [[ -n ${m_why[$id]+x} ]] || die "no mutant $id in $list"
  done
else
  selected=("${ids[@]}")
fi
if ((pick > 0)); then
  # Distinct mutants at places given by successive 8-hex-digit windows of the commit hash.
  hash=$(git -C "$repo" rev-parse HEAD 2>/dev/null) || die "--pick needs a git checkout"
  pool=("${selected[@]}")
  selected=()
  for ((w = 0; ${#selected[@]} < pick && ${#pool[@]} > 0; w++)); do
    at=$((16#${hash:$(((8 * w) % 33)):8} % ${#pool[@]}))
    selected+=("${pool[$at]}")
    pool=("${pool[@]:0:$at}" "${pool[@]:$((at + 1))}")
  done
  echo "== picked from commit ${hash:0:12}: ${selected[*]}"
fi

# Reads a file whole (every byte but NUL, trailing newlines included) into the variable named $2.
read_whole() { IFS= read -r -d '' "$2" < "$1" || true; }

# Sets where_count (occurrences of find in content) and where_line (the first one's line).
locate() {
  local content=$1 find=$2 rest prefix newlines
  rest=${content//"$find"/}
  where_count=$(((${#content} - ${#rest}) / ${#find}))
  where_line=0
  if ((where_count > 0)); then
    prefix=${content%%"$find"*}
    newlines=${prefix//[!$'\n']/}
    where_line=$((${#newlines} + 1))
  fi
}

# ---- --check: the list against the working tree ------------------------------------------------
if ((check_only)); then
  problems=0
  known_targets=$(grep -ho 'pcl_ddg_add_test(test_[a-z_0-9]*' "$repo/test/CMakeLists.txt" |
    sed 's/.*(//' | sort -u)
  for id in "${selected[@]}"; do
    file=$repo/${m_file[$id]}
    if [[ ! -f $file ]]; then
      echo "$id: no file ${m_file[$id]}"; problems=$((problems + 1)); continue
    fi
    read_whole "$file" content
    locate "$content" "${m_find[$id]}"
    if ((where_count != 1)); then
      echo "$id: '${m_find[$id]}' occurs $where_count times in ${m_file[$id]} (must be once)"
      problems=$((problems + 1))
    fi
    for t in ${m_tests[$id]}; do
      if [[ $t == pytest:* ]]; then
        path=${t#pytest:}
        [[ -f $repo/${path%%::*} ]] || {
          echo "$id: $t names no pytest file"; problems=$((problems + 1)); }
        continue
      fi
      grep -qx "$t" <<< "$known_targets" || {
        echo "$id: $t is not a test target of test/CMakeLists.txt"; problems=$((problems + 1)); }
    done
    ((where_count == 1)) && printf '%-5s %s:%d  %s\n' "$id" "${m_file[$id]}" "$where_line" "${m_why[$id]}"
  done
  echo "${#selected[@]} mutants checked, $problems problem(s)"
  ((problems == 0)) && exit 0 || exit 1
fi

# ---- scratch copy and build --------------------------------------------------------------------
command -v git > /dev/null || die "git is needed to list the source files"
command -v cmake > /dev/null || die "cmake is needed"
if [[ -n $reuse ]]; then
  scratch=$(realpath "$reuse") || die "no folder $reuse"
  [[ -d $scratch/build ]] || die "$scratch holds no build of an earlier run"
else
  scratch=$(mktemp -d "${TMPDIR:-/tmp}/pcl_ddg_mutants.XXXXXX") || die "mktemp failed"
fi
src=$scratch/src build=$scratch/build logs=$scratch/logs
if [[ -n $in_place ]]; then
  src=$repo
  build=$(realpath "$in_place") || die "no build folder $in_place"
  [[ -f $build/CMakeCache.txt ]] || die "$build is not a configured build"
fi
mkdir -p "$src" "$logs" "$scratch/tmp"

current_file=""   # the file a mutant is applied to, restored by restore_current
current_content=""
restore_current() {
  if [[ -n $current_file ]]; then
    printf '%s' "$current_content" > "$current_file"
    current_file=""
  fi
}
cleanup() {
  restore_current
  if [[ -n $in_place ]] && ((rebuild_after)) && [[ -s $scratch/rebuild ]]; then
    # The mutated targets, built again from the restored sources.
    # shellcheck disable=SC2046
    cmake --build "$build" -j"$jobs" --target $(sort -u "$scratch/rebuild") > "$logs/restore.log" 2>&1 ||
      echo "run_mutants: rebuilding $build after the mutants failed (log: $logs/restore.log)" >&2
  fi
  if ((keep)); then
    echo "run_mutants: scratch folder kept: $scratch (reuse it with --reuse $scratch)" >&2
  else
    rm -rf "$scratch"
  fi
}
trap cleanup EXIT
trap 'echo "run_mutants: interrupted" >&2; exit 130' INT TERM

start_all=$SECONDS
shared_data=${PCL_DDG_SHARED_DATA:-}
if [[ -z $shared_data ]]; then
  for candidate in "$repo/../shared/data" /work/shared/data; do
    [[ -f $candidate/CATALOG.md ]] && { shared_data=$(realpath "$candidate"); break; }
  done
fi
if [[ -z $in_place ]]; then
echo "== copying the source tree ($repo) to $src"
# Tracked files and untracked ones that are not ignored, as they are in the working tree; files
# deleted in the working tree are skipped. Modification times are kept, so that a --reuse run
# rebuilds only what changed.
(cd "$repo" && git ls-files -z --cached --others --exclude-standard |
  while IFS= read -r -d '' f; do [[ -f $f || -L $f ]] && printf '%s\0' "$f"; done |
  tar --null -T - -cf -) | tar -xf - -C "$src" || die "copying the source tree failed"
# Files mutated by an earlier run of this folder: newer than their objects, so they rebuild.
if [[ -f $scratch/touched ]]; then
  while IFS= read -r f; do [[ -f $src/$f ]] && touch "$src/$f"; done < "$scratch/touched"
  rm -f "$scratch/touched"
fi

generator=()
if [[ ! -f $build/CMakeCache.txt ]] && command -v ninja > /dev/null; then generator=(-G Ninja); fi
echo "== configuring $build (Release; tests and tools ON; benchmarks, fuzzers, viewer, examples OFF)"
cmake -S "$src" -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
  -DPCL_DDG_BUILD_TESTS=ON -DPCL_DDG_BUILD_TOOLS=ON -DPCL_DDG_BUILD_BENCHMARKS=OFF \
  -DPCL_DDG_BUILD_FUZZERS=OFF -DPCL_DDG_BUILD_VIEWER=OFF -DPCL_DDG_BUILD_EXAMPLES=OFF \
  ${shared_data:+"-DPCL_DDG_SHARED_DATA_DIR=$shared_data"} > "$logs/configure.log" 2>&1 ||
  { tail -n 30 "$logs/configure.log" >&2; die "configure failed (log: $logs/configure.log)"; }
echo "== building the unmutated tree (-j$jobs)"
build_start=$SECONDS
cmake --build "$build" -j"$jobs" > "$logs/build.log" 2>&1 ||
  { tail -n 40 "$logs/build.log" >&2; die "the unmutated tree does not build (log: $logs/build.log)"; }
echo "   built in $((SECONDS - build_start)) s"
else
  echo "== in place: $repo, built in $build"
fi

# ---- running tests -----------------------------------------------------------------------------
export TMPDIR=$scratch/tmp GTEST_COLOR=no  # F23: the tests' scratch names are per name only

# run_program TARGET FILTER TIMEOUT LOG: sets run_rc, run_seconds and run_failed (what failed).
run_program() {
  local target=$1 filter=$2 limit=$3 log=$4 start=$SECONDS args=()
  if [[ $target == pytest:* ]]; then
    (cd "$build" && PYTHONPATH=$build/python PCL_DDG_TOOLS_DIR=$build/tools \
      PCL_DDG_SHARED_DATA=$shared_data PCL_DDG_BUNDLED_DATA_DIR=$src/data \
      timeout -k 10 "$limit" /usr/bin/python3 -m pytest -q -x -p no:cacheprovider \
      "$src/${target#pytest:}") > "$log" 2>&1
    run_rc=$?
    run_seconds=$((SECONDS - start))
    run_failed=""
    ((run_rc == 0)) && return
    if ((run_rc == 124 || run_rc == 137)); then run_failed="timeout after ${limit} s"; return; fi
    run_failed=$(grep -E '^(FAILED|ERROR) ' "$log" | sed -E 's/^(FAILED|ERROR) ([^ ]+).*/\2/' |
      sed 's|.*/||' | sort -u | paste -sd' ' -)
    [[ -n $run_failed ]] || run_failed="pytest exit status $run_rc"
    return
  fi
  [[ -n $filter ]] && args=("--gtest_filter=$filter")
  (cd "$build/test" && timeout -k 10 "$limit" "./$target" "${args[@]}") > "$log" 2>&1
  run_rc=$?
  run_seconds=$((SECONDS - start))
  run_failed=""
  ((run_rc == 0)) && return
  if ((run_rc == 124 || run_rc == 137)); then
    run_failed="timeout after ${limit} s"
  else
    run_failed=$(grep -E '^\[  FAILED  \] [A-Za-z_0-9/.]+\.[A-Za-z_0-9/]+' "$log" |
      sed -E 's/^\[  FAILED  \] ([^ ,]+).*/\1/' | sort -u | paste -sd' ' -)
    if [[ -z $run_failed ]]; then
      if ((run_rc > 128)); then run_failed="crash (signal $((run_rc - 128)))"
      else run_failed="exit status $run_rc"; fi
    fi
  fi
}

# The test programs of the selected mutants, in first-use order.
declare -A program_seen baseline_seconds baseline_excluded
programs=()
for id in "${selected[@]}"; do
  for t in ${m_tests[$id]}; do
    [[ -n ${program_seen[$t]:-} ]] && continue
    program_seen[$t]=1
    programs+=("$t")
  done
done
# The targets a test entry needs built: its program, or for pytest the module and the tools.
targets_of() {
  local t
  for t in "$@"; do
    if [[ $t == pytest:* ]]; then
      echo pcl_ddg_python pcl_ddg_normals pcl_ddg_curvature pcl_ddg_info pcl_ddg_smooth
    else
      echo "$t"
    fi
  done | tr ' ' '\n' | sort -u
}
if [[ -n $in_place ]]; then
  # The build may have been made for other test groups: build the programs the mutants name.
  echo "== building the unmutated programs in $build"
  # shellcheck disable=SC2046
  cmake --build "$build" -j"$jobs" --target $(targets_of "${programs[@]}") > "$logs/build.log" 2>&1 ||
    { tail -n 40 "$logs/build.log" >&2; die "building the test programs failed (log: $logs/build.log)"; }
fi
baseline_failures=0
echo "== baseline: ${#programs[@]} unmutated test programs"
for t in "${programs[@]}"; do
  [[ $t == pytest:* || -x $build/test/$t ]] ||
    die "test program $t was not built (a target of test/CMakeLists.txt?)"
  # A pytest entry's path holds '/': its log is named with them turned into '_'.
  run_program "$t" "" "${timeout_override:-1800}" "$logs/baseline_${t//[\/:]/_}.log"
  baseline_seconds[$t]=$run_seconds
  if ((run_rc != 0)); then
    baseline_failures=$((baseline_failures + 1))
    echo "   $t FAILS UNMUTATED (${run_seconds} s): $run_failed" >&2
    if [[ $run_failed == *timeout* || $run_failed == crash* || $run_failed == exit* ]]; then
      die "baseline $t: $run_failed; cannot tell mutants apart (log: $logs/baseline_${t//[\/:]/_}.log)"
    fi
    baseline_excluded[$t]=${run_failed// /:}
  else
    printf '   %-34s %4d s\n' "$t" "$run_seconds"
  fi
done

# ---- the mutants -------------------------------------------------------------------------------
declare -A r_result r_where r_seconds r_by
killed=0 survived=0 errors=0 index=0
for id in "${selected[@]}"; do
  index=$((index + 1))
  start=$SECONDS
  rel=${m_file[$id]} file=$src/${m_file[$id]} find=${m_find[$id]} replace=${m_replace[$id]}
  r_where[$id]=$rel r_by[$id]="" r_result[$id]=""
  if [[ ! -f $file ]]; then
    r_result[$id]=ERROR r_by[$id]="no file $rel"
  else
    read_whole "$file" original
    locate "$original" "$find"
    r_where[$id]=$rel:$where_line
    if ((where_count != 1)); then
      r_result[$id]=ERROR r_by[$id]="the find text occurs $where_count times (must be once)"
    fi
  fi
  if [[ -z ${r_result[$id]} ]]; then
    current_file=$file current_content=$original
    echo "$rel" >> "$scratch/touched"
    printf '%s' "${original/"$find"/"$replace"}" > "$file"
    log=$logs/$id.log
    : > "$log"
    # shellcheck disable=SC2086
    mapfile -t targets < <(targets_of ${m_tests[$id]})
    [[ -n $in_place ]] && printf '%s\n' "${targets[@]}" >> "$scratch/rebuild"
    if ! cmake --build "$build" -j"$jobs" --target "${targets[@]}" > "$logs/${id}_build.log" 2>&1; then
      r_result[$id]=ERROR r_by[$id]="does not build (log: ${id}_build.log)"
    else
      r_result[$id]=survived
      for t in ${m_tests[$id]}; do
        filter=${m_filter[$id]:-}
        if [[ -n ${baseline_excluded[$t]:-} ]]; then
          filter="${filter:-*}-${baseline_excluded[$t]}"
        fi
        limit=${timeout_override:-$((4 * ${baseline_seconds[$t]} + 120))}
        run_program "$t" "$filter" "$limit" "$logs/${id}_${t//[\/:]/_}.log"
        if ((run_rc != 0)); then
          r_result[$id]=killed
          r_by[$id]+="${r_by[$id]:+; }$t: $run_failed"
          ((all_tests)) || break
        fi
      done
    fi
    restore_current
  fi
  r_seconds[$id]=$((SECONDS - start))
  case ${r_result[$id]} in
    killed) killed=$((killed + 1)) ;;
    survived) survived=$((survived + 1)) ;;
    *) errors=$((errors + 1)) ;;
  esac
  printf '[%d/%d] %-5s %-8s %4d s  %s  %s\n' "$index" "${#selected[@]}" "$id" "${r_result[$id]}" \
    "${r_seconds[$id]}" "${r_where[$id]}" "${r_by[$id]}"
done

# ---- the table ---------------------------------------------------------------------------------
table() {
  echo "| Mutant | File:line | Change | Result | s | Caught by |"
  echo "|---|---|---|---|---:|---|"
  for id in "${selected[@]}"; do
    local result=${r_result[$id]}
    [[ $result == survived ]] && result="**SURVIVED**"
    [[ $result == ERROR ]] && result="**ERROR**"
    local by=${r_by[$id]}
    [[ ${r_result[$id]} == survived ]] && by="(not caught by: ${m_tests[$id]})"
    by=${by//|/\\|}
    # "\::": Doxygen reads a bare "file.py::name" as a link to a symbol (Markdown shows "::").
    echo "| $id | ${r_where[$id]} | ${m_why[$id]//|/\\|} | $result | ${r_seconds[$id]} | ${by//::/\\::} |"
  done
  echo
  echo "Total: ${#selected[@]} mutants: $killed killed, $survived survived, $errors errors." \
    "Wall-clock $((SECONDS - start_all)) s (initial build included), -j$jobs."
  if ((baseline_failures)); then
    echo "Baseline: $baseline_failures test program(s) failed unmutated; their failing tests were" \
      "left out of the mutant runs:"
    for t in "${!baseline_excluded[@]}"; do echo "  $t: ${baseline_excluded[$t]//:/ }"; done
  fi
}
echo
table
if [[ -n $report ]]; then
  table > "$report"
  echo "(table written to $report)"
fi
((survived == 0 && errors == 0 && baseline_failures == 0)) && exit 0
exit 1
