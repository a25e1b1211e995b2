#!/usr/bin/env bash
# Side by side: DicePhys 2.81 as one process per core against dicephys on every core.
set -euo pipefail
# Usage: DP=path/to/dicephys-2.81 [US=target/release/dicephys] [N=1000] scripts/side-by-side.sh
# DicePhys is built outside this tree by ../shared/tools/build-dicephys.sh SRC OUT. Each round
# runs DicePhys (the paper's settings, 140x24x20) as 2 processes of N rolls, then dicephys's
# defaults on 2 threads over 20 N rolls, in 3D then 2D; three rounds alternated. Rolls per
# second over the wall time of each side; the ratio is throughput per 2-core machine.
DP=${DP:?set DP to the path of DicePhys 2.81 (its binary)}
US=${US:-target/release/dicephys}
N=${N:-1500}          # DicePhys rolls per process (2 processes)
M=$((2 * N * ${MULT:-10}))   # dicephys rolls (it is ~25x faster)
cd /tmp
for round in 1 2 3; do
  for mode in 3d 2d; do
    if [ "$mode" = 3d ]; then d=0.14; f=""; else d=0; f="--2d"; fi
    t0=$(date +%s.%N)
    for _ in 1 2; do "$DP" -v -0.2 0.2 -a 31 160 -y 0.2 0.4 -f 0.29 -r 0.5 -t 0.001 -w 0.024 -h 0.020 -d "$d" -D -n "$N" >/dev/null 2>&1 & done
    wait
    t1=$(date +%s.%N)
    # shellcheck disable=SC2086 # $f is empty or one word
    "$US" roll --block 140x24x20 $f --rolls "$M" --threads 2 --json > /tmp/us.json
    t2=$(date +%s.%N)
    python3 -c "
dp=2*$N/($t1-$t0); us=$M/($t2-$t1)
print('round $round $mode: DicePhys %.0f rolls/s (2 procs x $N), dicephys %.0f rolls/s ($M rolls, 2 threads): %.1fx' % (dp, us, us/dp))"
  done
done
