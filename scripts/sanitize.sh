#!/usr/bin/env bash
# A clang build under AddressSanitizer + UndefinedBehaviorSanitizer into
# ./build-asan, and a representative subset of the suite run in it (CI runs
# this after the Release tests; the whole suite: SANITIZE_ALL=1).
#   The subset: the loader and its bad-input and damaged-file tests, the
#   core kinematics/dynamics errors, the allocation-counting tests (counting
#   through the sanitizer's allocation hook), the simulator's failure paths,
#   contact events, the tree solver, appell run, and the fuzzers' findings.
# A short fuzz run of the scene loader is scripts/fuzz.sh -max_total_time=60.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/apt-install.sh sanitize clang libclang-rt-14-dev
SUBSET=(test_io_errors test_io_fuzz test_io_urdf test_io_scene test_io_fixed_links
        test_core_errors test_core_allocations test_simulator_alloc test_tree_solver_alloc
        test_simulator_failure test_contact_events test_tree_solver test_run test_fuzz_regressions)
CC=clang CXX=clang++ cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DAPPELL_SANITIZE=address,undefined -DAPPELL_BUILD_BENCHMARKS=OFF \
  -DAPPELL_BUILD_EXAMPLES=OFF -DAPPELL_BUILD_PYTHON=OFF >/dev/null
if [ "${SANITIZE_ALL:-0}" = 1 ]; then
  cmake --build build-asan -j"$(nproc)"
  filter=()
else
  cmake --build build-asan -j"$(nproc)" --target "${SUBSET[@]}" appell_cli
  # Every test carries its executable's name as a label (tests/CMakeLists.txt).
  filter=(-L "^($(IFS='|'; echo "${SUBSET[*]}"))\$")
fi
# Leaks inside third-party libraries are suppressed by name (fuzz/lsan.supp).
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 LSAN_OPTIONS=suppressions=$PWD/fuzz/lsan.supp
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
ctest --test-dir build-asan --output-on-failure -j"$(nproc)" -E 'package_consumer|viewer|python' "${filter[@]}"
