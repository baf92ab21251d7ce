#!/usr/bin/env bash
# Fuzzes the scene loader (and the mesh loader) with libFuzzer under ASan and
# UBSan, built with Debian's clang into ./build-asan (shared with
# scripts/sanitize.sh: one sanitized library serves both).
#   scripts/fuzz.sh                    10⁶ executions of the scene loader
#   scripts/fuzz.sh -runs=N            N executions
#   scripts/fuzz.sh -max_total_time=S  S seconds
#   FUZZ_TARGET=fuzz_mesh_loader scripts/fuzz.sh …   the mesh loader instead
# Seeds: every URDF of examples/ and tests/data (scene loader), every mesh of
# examples/, tests/data and fuzz/mesh-seeds (mesh loader: first byte = the
# file's suffix, the rest the file; the gate sniffs the format by content). A crash leaves
# crash-<sha1> in build-asan/findings; copy it to tests/data/fuzz-regressions/
# (test_fuzz_regressions loads each file there under every build).
set -euo pipefail
cd "$(dirname "$0")/.."
target=${FUZZ_TARGET:-fuzz_scene_loader}
# FUZZ_BUILT=1: the caller built the target already (scripts/sanitize.sh runs
# both fuzzers at once, one per core, and two builds of one tree must not race).
if [ "${FUZZ_BUILT:-0}" != 1 ]; then
  bash scripts/install-deps.sh
  bash scripts/configure-asan.sh
  cmake --build build-asan -j"$(nproc)" --target "$target"
fi
corpus=build-asan/corpus/$target
mkdir -p "$corpus" build-asan/findings
if [ "$target" = fuzz_scene_loader ]; then
  find examples tests/data -name '*.urdf' -size -64k -exec cp {} "$corpus"/ \;
else
  # First byte: the index of the file's suffix in fuzz_mesh_loader.cpp's
  # list (the content alone decides the format). fuzz/mesh-seeds holds a file
  # of each other format assimp recognises by content (NFF, AC3D, OFF, glTF,
  # X3D, Irrlicht, binary PLY), which the gate must refuse or read.
  i=0
  while IFS= read -r f; do
    case "$f" in *.stl|*.STL) b='\x00' ;; *.obj) b='\x01' ;; *.ply) b='\x02' ;; *.dae) b='\x03' ;;
                 *.nff) b='\x07' ;; *.ac) b='\x08' ;; *.off) b='\x09' ;; *.gltf) b='\x0a' ;; *.glb) b='\x0b' ;;
                 *) b='\x06' ;; esac
    { printf "$b"; cat "$f"; } > "$corpus/seed$i"; i=$((i + 1))
  done < <(find examples tests/data fuzz/mesh-seeds -type f \( -name '*.stl' -o -name '*.STL' -o -name '*.obj' \
             -o -name '*.ply' -o -name '*.dae' -o -path 'fuzz/mesh-seeds/*' -o -path 'tests/data/fuzz-regressions/mesh_*' \) -size -256k)
fi
args=("$@")
[ ${#args[@]} -eq 0 ] && args=(-runs=1000000)
# Bounded: inputs up to 64 KiB, 10 s per input, 2 GiB of memory.
# Leaks inside third-party libraries are suppressed by name (fuzz/lsan.supp).
ASAN_OPTIONS=detect_leaks=1 LSAN_OPTIONS=suppressions=fuzz/lsan.supp UBSAN_OPTIONS=print_stacktrace=1 \
  "./build-asan/fuzz/$target" -max_len=65536 -timeout=10 -rss_limit_mb=2048 \
  -artifact_prefix=build-asan/findings/ -print_final_stats=1 "${args[@]}" "$corpus"
