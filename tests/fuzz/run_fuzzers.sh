#!/usr/bin/env bash
# Builds the libFuzzer targets in their own clang build directory and runs each one in turn
# (docs/service.md#fuzzing).
#   tests/fuzz/run_fuzzers.sh --ci            what CI runs: every corpus input replayed, then a
#                                             fixed-seed exploration of 20000 inputs per target, so
#                                             that the gate fails only for a reason in the change
#   tests/fuzz/run_fuzzers.sh 60              60 seconds per target at random (finds new inputs:
#                                             a finding becomes a corpus entry once fixed)
#   tests/fuzz/run_fuzzers.sh --runs 1000000 [--max-time 600]   1 M executions per target
#   tests/fuzz/run_fuzzers.sh --seeds         regenerate tests/fuzz/corpus/ with fuzz_seed_gen
# Options: --targets "fuzz_a fuzz_b" (default: all), --build-only.
# Environment: FUZZ_BUILD_DIR (default build-fuzz), FUZZ_JOBS (build jobs, default 2).
# Each target starts from tests/fuzz/corpus/<target>/ (read only) and keeps what it finds in
# $FUZZ_BUILD_DIR/corpus/<target>/; a crash is saved in $FUZZ_BUILD_DIR/artifacts/<target>/ and
# makes the script fail. Fuzzers run one at a time under nice: the machine is shared.
set -euo pipefail
cd "$(dirname "$0")/../.."
ROOT=$PWD
BUILD_DIR=${FUZZ_BUILD_DIR:-build-fuzz}
JOBS=${FUZZ_JOBS:-2}
ALL_TARGETS="fuzz_image_decode fuzz_webp_decode fuzz_rest_request fuzz_grpc_request fuzz_oip_request fuzz_model_files fuzz_manifest
  fuzz_mask_reader fuzz_laf_reader fuzz_modd2_mat"

seconds=5
runs=""
seed=()
ci=0
max_time=0
targets=$ALL_TARGETS
seeds=0
build_only=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    --runs) runs=$2; shift 2 ;;
    --ci) ci=1; runs=20000; max_time=300; seed=(-seed=1); shift ;;
    --max-time) max_time=$2; shift 2 ;;
    --targets) targets=$2; shift 2 ;;
    --seeds) seeds=1; shift ;;
    --build-only) build_only=1; shift ;;
    [0-9]*) seconds=$1; shift ;;
    *) sed -n '2,15p' "$0" >&2; exit 2 ;;
  esac
done

for tool in clang clang++; do
  command -v "$tool" >/dev/null || { echo "run_fuzzers.sh: $tool not found (deploy/deps.sh build)" >&2; exit 1; }
done

launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
if [[ ! -f $BUILD_DIR/build.ninja ]]; then
  CC=clang CXX=clang++ cmake -S . -B "$BUILD_DIR" -G Ninja -DTOD_FUZZ=ON -DTOD_BUILD_TESTS=OFF \
    -DTOD_LTO=OFF -DCMAKE_BUILD_TYPE=Fuzz "${launcher[@]}" >/dev/null
fi
start=$SECONDS
nice cmake --build "$BUILD_DIR" --target fuzzers -j "$JOBS"
echo "run_fuzzers.sh: fuzz targets built in $((SECONDS - start)) s"

if [[ $seeds -eq 1 ]]; then
  rm -rf tests/fuzz/corpus.new
  "$BUILD_DIR/bin/fuzz_seed_gen" tests/fuzz/corpus.new
  # Keep the regression inputs (crashes found earlier): they are corpus entries too.
  for dir in tests/fuzz/corpus/*/; do
    target=$(basename "$dir")
    for f in "$dir"crash-* "$dir"oom-* "$dir"timeout-*; do
      [[ -e $f ]] && mkdir -p "tests/fuzz/corpus.new/$target" && cp "$f" "tests/fuzz/corpus.new/$target/"
    done
  done
  rm -rf tests/fuzz/corpus && mv tests/fuzz/corpus.new tests/fuzz/corpus
  du -sh tests/fuzz/corpus
  exit 0
fi
[[ $build_only -eq 1 ]] && exit 0

# libFuzzer's own flags: a 2 GB RSS limit (a loader must refuse a huge claim, not allocate it),
# 25 s per input, no leak checking per input (the gRPC library keeps process-wide state).
common=(-rss_limit_mb=2048 -timeout=25 -print_final_stats=1 -detect_leaks=0)
# The leak check at exit still runs; leaks inside libraries that are not ours are suppressed
# there, each with its reason in the file.
export LSAN_OPTIONS="suppressions=$ROOT/tests/fuzz/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
if [[ -n $runs ]]; then
  limit=(-runs="$runs" -max_total_time="$max_time")
else
  limit=(-max_total_time="$seconds")
fi

failed=()
summary=()
for target in $targets; do
  work=$BUILD_DIR/corpus/$target
  # --ci starts from the project's corpus alone every time: what an earlier run kept would make
  # the result depend on the build directory's history.
  [[ $ci -eq 1 ]] && work=$BUILD_DIR/corpus-ci/$target && rm -rf "$work"
  artifacts=$BUILD_DIR/artifacts/$target/
  mkdir -p "$work" "$artifacts"
  dict=()
  [[ -f tests/fuzz/dict/$target.dict ]] && dict=(-dict="tests/fuzz/dict/$target.dict")
  log=$BUILD_DIR/$target.log
  if [[ -n $runs ]]; then
    echo "run_fuzzers.sh: $target: $runs runs (time limit: ${max_time} s, 0 = none)"
  else
    echo "run_fuzzers.sh: $target: $seconds s"
  fi
  status=0
  nice "$BUILD_DIR/bin/$target" "${common[@]}" "${seed[@]}" "${limit[@]}" "${dict[@]}" \
    -artifact_prefix="$artifacts" "$work" "tests/fuzz/corpus/$target" >"$log" 2>&1 || status=$?
  # (|| true: a target that fails before its first status line prints none of these)
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1 || true)
  secs=$(sed -n 's/^Done [0-9]* runs in \([0-9]*\) second.*/\1/p' "$log" | tail -1 || true)
  cov=$({ grep -o 'cov: [0-9]*' "$log" || true; } | tail -1 | cut -d' ' -f2)
  if [[ $status -ne 0 ]]; then
    failed+=("$target")
    echo "run_fuzzers.sh: $target FAILED (exit $status); log: $log, input: $(ls -t "$artifacts" | head -1)" >&2
    grep -m 20 -E 'ERROR|SUMMARY|#[0-9]+ 0x' "$log" >&2 || true
  fi
  summary+=("$(printf '%-20s %12s execs %6s s  cov %6s  %s' "$target" "${execs:-?}" "${secs:-?}" \
    "${cov:-?}" "$([[ $status -eq 0 ]] && echo ok || echo FAILED)")")
done
printf '%s\n' "${summary[@]}"
if [[ ${#failed[@]} -gt 0 ]]; then
  echo "run_fuzzers.sh: failed: ${failed[*]}" >&2
  exit 1
fi
