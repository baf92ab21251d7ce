#!/usr/bin/env bash
# Runs every example scene (examples/*/*.urdf) with two appell CLIs and
# compares the trajectories byte for byte: the check that a refactoring left
# the simulation bit-identical (same CSV, same exit code).
#
#   scripts/compare_trajectories.sh BASE_CLI NEW_CLI [DURATION] [OUT_DIR]
#
# BASE_CLI, NEW_CLI: appell executables (e.g. a worktree of the base commit
# built like this one, and build/cli/appell). DURATION: simulated seconds per
# scene (default 2), or "scene" for each scene's own duration. OUT_DIR keeps the CSVs, logs and exit codes;
# give "-" for a CLI whose side is already there (run the base once, compare
# many times). Exit status 1 when any scene differs.
#
# A run the stall watchdog stops (run/src/stall_watch.cpp: wall-clock time)
# ends where the machine's load let it get. The automatic scheme's switch to
# time-stepping no longer depends on the wall clock (docs/contacts.md §10:
# it counts the simulation's work), so a run that finishes is reproducible bit for bit.
set -u
abs() { [ "$1" = - ] && echo - || echo "$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"; }
base=$(abs "$1")
new=$(abs "$2")
duration=${3:-2}
out=${4:-$(mktemp -d)}
span=(--duration "$duration")
[ "$duration" = scene ] && span=()
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$out"
status=0
for scene in "$root"/examples/*/*.urdf; do
  name=$(basename "$scene" .urdf)
  for side in base new; do
    cli=$base
    [ "$side" = new ] && cli=$new
    [ "$cli" = - ] && continue  # "-": that side's results are already in OUT_DIR
    (cd "$(dirname "$scene")" &&
      "$cli" run "$scene" "${span[@]}" --quiet --out "$out/$name.$side.csv" \
        >"$out/$name.$side.log" 2>&1
      echo $? >"$out/$name.$side.rc")
  done
  [ -f "$out/$name.base.rc" ] && [ -f "$out/$name.new.rc" ] || continue
  rc_base=$(cat "$out/$name.base.rc")
  rc_new=$(cat "$out/$name.new.rc")
  if [ "$rc_base" != "$rc_new" ]; then
    echo "DIFFERS  $name: exit $rc_base vs $rc_new"
    status=1
  elif [ ! -f "$out/$name.base.csv" ]; then
    echo "no csv   $name (exit $rc_base in both)"
  elif cmp -s "$out/$name.base.csv" "$out/$name.new.csv"; then
    echo "same     $name ($(wc -l <"$out/$name.new.csv") rows, exit $rc_new)"
  else
    echo "DIFFERS  $name: $(cmp "$out/$name.base.csv" "$out/$name.new.csv" | head -1)"
    status=1
  fi
done
exit $status
