#!/bin/bash
# renders.sh BIN OUT: image sha256 and counters of bvh8 without packets, packet=8 and packet=16
# at 256², one thread: the scenes session 7 listed (SF given) and the 7 standard scenes.
BIN=$1; OUT=$2; : > $OUT
cd "$(git rev-parse --show-toplevel)"
for SSF in balls:3 tetra:5 rings:3 teapot:6 tree:8 mount:4 gears:3 balls: gears: mount: rings: teapot: tetra: tree:; do
  S=${SSF%%:*}; F=${SSF#*:}; SF=${F:+--sf $F}
  for P in off 8 16; do
    taskset -c 1 $BIN render --scene $S $SF --engine bvh8 --threads 1 --size 256 --json --set packet=$P 2>/dev/null | python3 -c "
import json,sys; j=json.load(sys.stdin); c=j['counters']
print('$S${F:-std} packet=$P', j['image']['sha256'][:16], c['nodes_visited'], c['box_tests'], c['primitive_tests'], c['primitive_hits'], c['rays'])" >> $OUT
  done
done
