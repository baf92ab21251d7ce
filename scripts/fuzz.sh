#!/usr/bin/env bash
# Fuzzes the scene loader (and the mesh loader) with libFuzzer under ASan and
# UBSan, built with Debian's clang into ./build-asan (shared with
# scripts/sanitize.sh: one sanitized library serves both).
#   scripts/fuzz.sh                    10⁶ executions of the scene loader
#   scripts/fuzz.sh -runs=N            N executions
#   scripts/fuzz.sh -max_total_time=S  S seconds
#   FUZZ_TARGET=fuzz_mesh_loader scripts/fuzz.sh …   the mesh loader instead
# Seeds: every URDF of examples/ and tests/data (scene loader), every mesh of
# examples/ and tests/data (mesh loader: first byte = format). A crash leaves
# crash-<sha1> in build-asan/findings; copy it to tests/data/fuzz-regressions/
# (test_fuzz_regressions loads each file there under every build).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
target=${FUZZ_TARGET:-fuzz_scene_loader}
bash scripts/configure-asan.sh
cmake --build build-asan -j"$(nproc)" --target "$target"
corpus=build-asan/corpus/$target
mkdir -p "$corpus" build-asan/findings
if [ "$target" = fuzz_scene_loader ]; then
  find examples tests/data -name '*.urdf' -size -64k -exec cp {} "$corpus"/ \;
else
  i=0
  while IFS= read -r f; do
    case "$f" in *.stl|*.STL) b='\x00' ;; *.obj) b='\x01' ;; *.ply) b='\x02' ;; *.dae) b='\x03' ;; *) continue ;; esac
    { printf "$b"; cat "$f"; } > "$corpus/seed$i"; i=$((i + 1))
  done < <(find examples tests/data -type f \( -name '*.stl' -o -name '*.STL' -o -name '*.obj' -o -name '*.ply' -o -name '*.dae' \) -size -256k)
fi
args=("$@")
[ ${#args[@]} -eq 0 ] && args=(-runs=1000000)
# Bounded: inputs up to 64 KiB, 10 s per input, 2 GiB of memory.
# Leaks inside third-party libraries are suppressed by name (fuzz/lsan.supp).
ASAN_OPTIONS=detect_leaks=1 LSAN_OPTIONS=suppressions=fuzz/lsan.supp UBSAN_OPTIONS=print_stacktrace=1 \
  "./build-asan/fuzz/$target" -max_len=65536 -timeout=10 -rss_limit_mb=2048 \
  -artifact_prefix=build-asan/findings/ -print_final_stats=1 "${args[@]}" "$corpus"
