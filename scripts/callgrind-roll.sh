#!/usr/bin/env bash
# The plain roll's instruction count under callgrind, held against a reference: instructions,
# not seconds, so that a shared and noisy machine still says whether a change made the roll
# slower. Builds nothing: give it the binary to measure.
#
#   scripts/callgrind-roll.sh [BIN] [OUT_DIR]
#
# BIN defaults to target/release/dicephys (of this checkout); OUT_DIR, where callgrind's file
# (callgrind.out) and the roll's JSON (roll.json) are kept, to a temporary directory removed
# at exit. Runs the referee command
#
#   valgrind --tool=callgrind --callgrind-out-file=OUT BIN roll --block 140x24x20 \
#     --rolls 1000 --threads 1 --seed 1 --json > OUT.json
#
# prints its total instruction count beside the reference, and exits 1 if the count is above
# the reference by more than TOLERANCE_PERCENT (2 if it could not measure). Look at where the
# instructions go with callgrind_annotate OUT_DIR/callgrind.out (--inclusive=yes, --auto=yes).
#
# The reference holds for the build below: another rustc or profile counts differently, so
# after an upgrade measure the tree before the change again and update all three values.
set -euo pipefail

# Instructions of the referee command, from a release build (Cargo.toml's [profile.release]:
# line tables for this crate, no debug information for the others) with the plain roll's fast
# paths (the commit "BodyState::is_finite in one test"). The same tree built with debug = 1
# (the profile until issue 50) counted 980,639,964: the profile alone moves it by +0.3 %, the
# rolls bit for bit the same. Before the fast paths, at 3e0c75f, 1,039,834,333 (debug = 1).
REFERENCE=983615226
REFERENCE_RUSTC="rustc 1.95.0 (59807616e 2026-04-14)"
REFERENCE_PROFILE="release, debug = line-tables-only (dependencies: none)"
TOLERANCE_PERCENT=1

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin=${1:-$root/target/release/dicephys}
if [[ ! -x $bin ]]; then
  echo "callgrind-roll: no binary at $bin (this script builds nothing: cargo build --release)" >&2
  exit 2
fi
if ! command -v valgrind > /dev/null; then
  echo "callgrind-roll: valgrind not found" >&2
  exit 2
fi
if [[ -n ${2:-} ]]; then
  out=$2
  mkdir -p "$out"
else
  out=$(mktemp -d)
  trap 'rm -rf "$out"' EXIT
fi

valgrind --tool=callgrind --callgrind-out-file="$out/callgrind.out" "$bin" roll \
  --block 140x24x20 --rolls 1000 --threads 1 --seed 1 --json \
  > "$out/roll.json" 2> "$out/valgrind.log"
count=$(sed -n 's/^summary: *\([0-9][0-9]*\).*/\1/p' "$out/callgrind.out")
if [[ -z $count ]]; then
  echo "callgrind-roll: no total in $out/callgrind.out (valgrind's log: $out/valgrind.log)" >&2
  exit 2
fi

limit=$((REFERENCE + REFERENCE * TOLERANCE_PERCENT / 100))
change=$(awk -v c="$count" -v r="$REFERENCE" 'BEGIN { printf "%+.2f", 100 * (c - r) / r }')
rustc_now=$(rustc -V 2> /dev/null || echo "rustc not found")
echo "instructions: $count"
echo "reference:    $REFERENCE ($change %; limit $limit, +$TOLERANCE_PERCENT %)"
echo "  measured with $REFERENCE_RUSTC, $REFERENCE_PROFILE"
if [[ $rustc_now != "$REFERENCE_RUSTC" ]]; then
  echo "  note: this machine's compiler is $rustc_now: the reference may not hold for it"
fi
if ((count > limit)); then
  echo "FAIL: more than $TOLERANCE_PERCENT % above the reference"
  exit 1
fi
echo "ok"
