#!/usr/bin/env bash
# A clang build under AddressSanitizer + UndefinedBehaviorSanitizer (with
# libFuzzer's coverage, so the fuzz targets share it) into ./build-asan, a
# representative subset of the suite run in it, then a bounded fuzz run of
# the scene loader and one of the mesh loader (FUZZ_SECONDS each, default
# 30; 0 skips them). scripts/test.sh
# runs this after the Release tests, so CI does.
#   The subset: the loader's bad-input, damaged-file and fuzz-finding tests,
#   the model builder's errors, the allocation-counting tests (counting
#   through the sanitizer's allocation hook), the simulator's failure paths
#   and `appell run` end to end (4 programs, 5 min of the ~8 this takes on
#   2 cores is the sanitized library). The whole suite: SANITIZE_ALL=1.
#   scripts/sanitize.sh --build  only configure and build (the subset, `appell`
#                                and the two fuzz targets)
#   scripts/sanitize.sh --test   configure, build and run the subset, no fuzzing:
#                                scripts/test.sh runs this beside the Release
#                                build, at lower priority, so the sanitized
#                                tests run while the Release build still compiles
#   scripts/sanitize.sh --fuzz   only the two fuzz runs (built before): test.sh
#                                runs them after the Release tests, on both cores
set -euo pipefail
cd "$(dirname "$0")/.."
step=${1:-all}
case "$step" in all|--build|--test|--fuzz) ;; *) echo "sanitize.sh: unknown option $step" >&2; exit 2;; esac
bash scripts/install-deps.sh
# test_failures: the files named in tests/CMakeLists.txt's group of that name.
SUBSET=(test_failures test_core_allocations test_simulator_alloc test_tree_solver_alloc)
FUZZERS=(fuzz_scene_loader fuzz_mesh_loader)
if [ "$step" != --fuzz ]; then
  bash scripts/configure-asan.sh
  # One ninja run for everything this script needs: the fuzz targets' sources
  # compile beside the tests' instead of after the test runs.
  if [ "${SANITIZE_ALL:-0}" = 1 ]; then
    cmake --build build-asan -j"$(nproc)"
    filter=()
  else
    cmake --build build-asan -j"$(nproc)" --target "${SUBSET[@]}" appell_cli "${FUZZERS[@]}"
    # Every test carries its executable's name as a label (tests/CMakeLists.txt).
    filter=(-L "^($(IFS='|'; echo "${SUBSET[*]}"))\$")
  fi
  [ "$step" = --build ] && exit 0
  # Leaks inside third-party libraries are suppressed by name (fuzz/lsan.supp).
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 LSAN_OPTIONS=suppressions=$PWD/fuzz/lsan.supp
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  ctest --test-dir build-asan --output-on-failure -j"$(nproc)" -E 'package_consumer|viewer|python' "${filter[@]}"
fi
[ "$step" = --test ] && exit 0
# A fixed seed (FUZZ_SEED, default 1): CI explores the same inputs every run,
# so a red CI is a change's doing and reproduces; scripts/fuzz.sh alone draws
# a new seed each time, for exploring.
seconds=${FUZZ_SECONDS:-30}
seed=${FUZZ_SEED:-1}
if [ "$seconds" != 0 ]; then
  # The scene loader and the mesh gate (every format assimp recognises by
  # content, under any name) at once, one per core: the 2×30 s take 30 s.
  FUZZ_BUILT=1 bash scripts/fuzz.sh -max_total_time="$seconds" -seed="$seed" \
    > build-asan/fuzz_scene_loader.log 2>&1 &
  scene=$!
  FUZZ_BUILT=1 FUZZ_TARGET=fuzz_mesh_loader bash scripts/fuzz.sh -max_total_time="$seconds" \
    -seed="$seed" > build-asan/fuzz_mesh_loader.log 2>&1 &
  mesh=$!
  status=0
  wait "$scene" || status=1
  wait "$mesh" || status=1
  # libFuzzer's summary (and any finding's report) of each run.
  for t in fuzz_scene_loader fuzz_mesh_loader; do
    echo "== $t"; grep -E '^(Done|stat::|==|SUMMARY|INFO: Seed)|ERROR|Test unit written' "build-asan/$t.log" || true
  done
  if [ "$status" != 0 ]; then
    echo "sanitize: a fuzz run failed; its whole output is in build-asan/fuzz_*.log" >&2
    tail -n 40 build-asan/fuzz_scene_loader.log build-asan/fuzz_mesh_loader.log >&2
    exit 1
  fi
fi
