#!/bin/bash
# checks.sh BIN OUT: rtbench check summary, 4 scenes x bvh4/bvh8, 256², one thread
BIN=$1; OUT=$2; : > $OUT
cd "$(git rev-parse --show-toplevel)"
for S in gears tetra balls teapot; do for E in bvh4 bvh8; do
  taskset -c 1 $BIN check --scene $S --engine $E --threads 1 --size 256 --json 2>/dev/null | python3 -c "
import json,sys; j=json.load(sys.stdin)
print('$S $E', j['hit_agreement'], j['disagreements'], j['image_psnr_db'], j['t_rel_err']['max'], j['t_rel_err']['median'], j['pass'])" >> $OUT
done; done
