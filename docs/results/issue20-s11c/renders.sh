#!/bin/bash
# renders.sh BIN OUT: sha + counters of bvh4/bvh8 on the 7 standard scenes at 256², one thread
BIN=$1; OUT=$2; : > $OUT
cd "$(git rev-parse --show-toplevel)"
for S in balls gears mount rings teapot tetra tree; do for E in bvh4 bvh8; do
  taskset -c 1 $BIN render --scene $S --engine $E --threads 1 --size 256 --json 2>/dev/null | python3 -c "
import json,sys; j=json.load(sys.stdin); c=j['counters']
print('$S $E', j['image']['sha256'][:16], c['nodes_visited'], c['box_tests'], c['primitive_tests'], c['primitive_hits'], c['rays'])" >> $OUT
done; done
