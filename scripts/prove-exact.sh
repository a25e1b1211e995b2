#!/bin/sh
# Proof that a speed change leaves every roll as it was: the per-roll CSVs of two dicephys
# binaries, on the same keyed throws of each MDF block in 2D and 3D, compared byte for byte
# (outcome, steps, simulated time, flags: every column).
#
#   scripts/prove-exact.sh OLD_BIN NEW_BIN [ROLLS] [ENGINE] [EXTRA ROLL FLAGS...]
#
# e.g. cp target/release/dicephys /tmp/dicephys-before   (before the change)
#      scripts/prove-exact.sh /tmp/dicephys-before target/release/dicephys 20000
# Prints one line per cell and exits 1 if any cell differs.
set -eu
old=$1; new=$2; rolls=${3:-20000}; engine=${4:-bullet}
shift $(( $# < 4 ? $# : 4 ))
dir=$(mktemp -d); trap 'rm -rf "$dir"' EXIT
bad=0
for block in 140x24x20 140x22x13 140x27x13 140x29x11 140x30x10; do
  for mode in 3d 2d; do
    flag=""; [ "$mode" = 2d ] && flag="--2d"
    for b in old new; do
      if [ "$b" = old ]; then bin=$old; else bin=$new; fi
      # shellcheck disable=SC2086 # $flag is empty or one word
      "$bin" roll --block "$block" $flag --rolls "$rolls" --seed 10 --engine "$engine" \
        --threads 1 --per-roll "$dir/$b.csv" "$@" > /dev/null
    done
    n=$(($(wc -l < "$dir/old.csv") - 1))
    same=$(paste -d'|' "$dir/old.csv" "$dir/new.csv" | tail -n +2 | awk -F'|' '$1 == $2' | wc -l)
    echo "$engine $block $mode: $same of $n rows identical"
    [ "$same" -eq "$n" ] && [ "$n" -eq "$rolls" ] || bad=1
  done
done
exit $bad
