#!/usr/bin/env bash
# Regenerates every benchmark figure and report under bench/results:
#   - each Google Benchmark program (bench/bm_*.cpp) → bench/results/data/NAME.json
#     and its table of medians bench/results/tables/NAME.md (bench/tables.py);
#   - the report programs → speed_error.{csv,gp,png} (+ tables/speed_error.md),
#     long_run.{md,csv,gp,png}, peers.{md,csv,gp,png}, peers_vehicles.md, fc3d.md;
#   - the Python bindings' thread scaling (python/bench/thread_scaling.py)
#     → tables/thread_scaling.md;
#   - `appell info`'s wall time per description (bench/report_info_times.py)
#     → info_times.md (published robots timed when ROS_PACKAGE_PATH is set);
#   - the peers (Simbody, MuJoCo, Siconos) are installed first (scripts/install-peers.sh).
# Each page names the command that made it. The analyses in bench/RESULTS.md
# and bench/results/*.md quote dated runs and link to these pages.
#
# One program at a time: two at once share the memory bus as well as the
# machine's other load. Tried: the 10⁶-step long run on one core beside the
# rest on the other took 6 min instead of 8, and its tree-solver ratio at
# 1024 bodies read 3.02 — within the spread these timings have anyway on a
# shared machine (2.20–3.03 over four runs, three of them alone), so the
# lanes bought 2 minutes at the price of one more source of noise.
#   bash scripts/bench.sh          everything (≈ 8 min on 2 cores after the build)
#   bash scripts/bench.sh NAME…    only those programs, one after another
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-peers.sh
APPELL_CMAKE_ARGS="-DAPPELL_BUILD_BENCHMARKS=ON" bash scripts/build.sh >/dev/null   # every target, report_peers included once the peers are there
OUT=bench/results
mkdir -p "$OUT/data" "$OUT/tables"

# Repetitions and minimum times keep the whole command within 10 minutes on
# 2 cores; each program's page says what its numbers mean.
GB="--benchmark_repetitions=3 --benchmark_report_aggregates_only=true"
SPEED_SCENES="examples/rolling_disk/rolling_disk.urdf examples/sleigh/sleigh.urdf examples/hemisphere_bowl/hemisphere_bowl.urdf"
declare -A ARGS=(
  [bm_dynamics]="$GB --benchmark_min_time=0.05"
  [bm_constrained_scaling]="$GB --benchmark_min_time=0.05"
  [bm_events]="$GB"
  [bm_friction]="$GB"
  [bm_collision]="$GB --benchmark_min_time=0.1"
  [bm_evaluation]="$GB --benchmark_min_time=0.2"
  [bm_parallel]="$GB"
  [report_speed_error]="--repeats 3 --out $OUT $SPEED_SCENES"
  [report_long_run]="--steps 1000000 --dt 0.01 --out $OUT"
  [report_peers]="--repeats 3 --out $OUT"
  [report_peers_vehicles]="--repeats 3 --out $OUT"
  [report_fc3d]="--repeats 3 --out $OUT"
  [thread_scaling]="--repeat 5"
  [report_info_times]="--repeats 5 --out $OUT/info_times.md"
)

# run NAME: one program, its output where its page expects it.
run() {
  local name=$1 exe=build/bench/$1 start
  [ -n "${ARGS[$name]+x}" ] || { echo "bench.sh: no benchmark named '$name' (one of: ${!ARGS[*]})" >&2; return 2; }
  [ "$name" = report_peers ] && exe=build/bench/peers/report_peers
  [ "$name" = report_peers_vehicles ] && exe=build/bench/peers/report_peers_vehicles
  [ "$name" = report_fc3d ] && exe=build/bench/peers/report_fc3d
  [ "$name" = thread_scaling ] && exe=python/bench/thread_scaling.py
  [ "$name" = report_info_times ] && exe=bench/report_info_times.py
  [ -e "$exe" ] || { echo "bench.sh: $exe was not built" >&2; return 1; }
  start=$(date +%s)
  local -a args
  read -r -a args <<< "${ARGS[$name]}"
  if [[ $name == bm_* ]]; then
    "$exe" "${args[@]}" --benchmark_out="$OUT/data/$name.json" --benchmark_out_format=json \
      > "$OUT/data/$name.log" 2>&1
    /usr/bin/python3 bench/tables.py "$OUT/data/$name.json" "$exe ${ARGS[$name]}" "$OUT/tables/$name.md"
  elif [ "$name" = report_info_times ]; then
    /usr/bin/python3 "$exe" --cli build/cli/appell "${args[@]}" > "$OUT/data/$name.log" 2>&1
  elif [ "$name" = thread_scaling ]; then
    PYTHONPATH=build/python /usr/bin/python3 "$exe" "${args[@]}" > "$OUT/data/$name.log" 2>&1
    /usr/bin/python3 bench/tables.py "$OUT/data/$name.log" \
      "PYTHONPATH=build/python /usr/bin/python3 $exe ${ARGS[$name]}" "$OUT/tables/$name.md"
  else
    "$exe" "${args[@]}" > "$OUT/data/$name.log" 2>&1
    if [ "$name" = report_speed_error ]; then
      /usr/bin/python3 bench/tables.py "$OUT/speed_error.csv" "$exe ${ARGS[$name]}" "$OUT/tables/speed_error.md"
    fi
  fi
  echo "bench.sh: $name done in $(( $(date +%s) - start )) s"
}

ALL=(bm_dynamics bm_evaluation bm_constrained_scaling bm_events bm_friction bm_collision bm_parallel
     report_speed_error report_long_run report_peers report_peers_vehicles report_fc3d thread_scaling report_info_times)
total_start=$(date +%s)
for name in "${@:-${ALL[@]}}"; do run "$name"; done
echo "bench.sh: all done in $(( $(date +%s) - total_start )) s; results in $OUT"
