#!/usr/bin/env bash
# Long runs (issue 17, item 6), outside the default test set: 10⁶ RK4 steps
# (dt 1e-3, 1000 s) of the rolling disk, the Chaplygin sleigh (on level
# ground) and the four-wheeled car, each also run for 10⁵ steps. Checks that
# the energy error and the constraint residuals stay bounded over 10⁶ steps
# and that memory is flat (peak RSS of the 10⁶-step run within 10 % of the
# 10⁵-step one). Prints a table; exits 1 if a bound is broken.
#   bash scripts/long-run.sh          (about a minute on 2 cores after the build)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh appell_cli >/dev/null
APPELL=./build/cli/appell
SCENES=(examples/rolling_disk/rolling_disk.urdf tests/data/long_run/sleigh_level.urdf examples/car/car.urdf)
MAX_ENERGY=1e-9     # relative energy error over 1000 s
MAX_RESIDUAL=1e-10  # max |Av+b| and max |gap|
status=0
printf '%-45s %9s %12s %12s %12s %10s\n' scene steps "rel. energy" "max |Av+b|" "max |gap|" "peak RSS"
for scene in "${SCENES[@]}"; do
  declare -A rss=()
  for duration in 100 1000; do
    out=$( { /usr/bin/time -f 'peak-rss %M' "$APPELL" run "$scene" --integrator rk4 --dt 1e-3 \
             --duration "$duration" --quiet; } 2>&1 ) || { echo "$scene: run failed"; echo "$out"; exit 1; }
    steps=$(sed -n 's/^simulated .* in \([0-9]*\) steps.*/\1/p' <<<"$out")
    energy=$(sed -n 's/.*(\([0-9.eE+-]*\) relative).*/\1/p' <<<"$out")
    vres=$(sed -n 's/.*max |Av+b| = \([0-9.eE+-]*\),.*/\1/p' <<<"$out")
    gres=$(sed -n 's/.*max |gap| = \([0-9.eE+-]*\).*/\1/p' <<<"$out")
    rss[$duration]=$(sed -n 's/^peak-rss \([0-9]*\)$/\1/p' <<<"$out")
    printf '%-45s %9s %12s %12s %12s %8s kB\n' "$scene" "$steps" "$energy" "$vres" "$gres" "${rss[$duration]}"
    if ! awk -v e="$energy" -v v="$vres" -v g="$gres" -v me="$MAX_ENERGY" -v mr="$MAX_RESIDUAL" \
         'BEGIN { exit !(e <= me && v <= mr && g <= mr) }'; then
      echo "  ✗ beyond the bounds (energy $MAX_ENERGY, residuals $MAX_RESIDUAL)"; status=1
    fi
  done
  if ! awk -v a="${rss[100]}" -v b="${rss[1000]}" 'BEGIN { exit !(b <= 1.1 * a) }'; then
    echo "  ✗ memory grew from ${rss[100]} kB to ${rss[1000]} kB"; status=1
  fi
done
exit $status
