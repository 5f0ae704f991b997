#!/bin/bash
# renders-set.sh BIN OUT SIZE [SET...]: sha + counters of bvh4/bvh8 on the 7 standard scenes, one thread
BIN=$1; OUT=$2; SIZE=$3; shift 3; SETS=""; for s in "$@"; do SETS="$SETS --set $s"; done; : > $OUT
for S in balls gears mount rings teapot tetra tree; do for E in bvh4 bvh8; do
  taskset -c 1 $BIN render --scene $S --engine $E --threads 1 --size $SIZE $SETS --json 2>/dev/null | python3 -c "
import json,sys; j=json.load(sys.stdin); c=j['counters']
print('$S $E', j['image']['sha256'][:16], c['nodes_visited'], c['box_tests'], c['primitive_tests'], c['primitive_hits'], c['rays'])" >> $OUT
done; done
