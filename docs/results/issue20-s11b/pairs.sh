#!/bin/bash
# usage: pairs.sh OUTFILE RUNS bin1 [bin2 ...]  -- alternates binaries within each run index
# BIN_DIR: a directory holding the binaries to compare, named rtbench-<name> (here rtbench-base = b7c741f, rtbench-b2 = e390729).
out=$1; runs=$2; shift 2
for r in $(seq 1 $runs); do
 for s in balls4 gears4 mount6 rings7 teapot12 tetra6 tree11; do
  sc=${s%%[0-9]*}; sf=${s##*[a-z]}
  for e in bvh8 bvh4 grid; do
   for b in "$@"; do
    j=$(taskset -c 1 "$BIN_DIR"/rtbench-$b render --scene $sc --sf $sf --engine $e --threads 1 --size 512 --json 2>/dev/null)
    echo "$j" | python3 -c "
import json,sys,hashlib
d=json.load(sys.stdin)
h=hashlib.sha256((json.dumps(d['counters'],sort_keys=True)+json.dumps(d['rays'],sort_keys=True)).encode()).hexdigest()[:16]
m=d['memory']
print('$r','$b','$s','$e',m['structure_bytes'],m['peak_rss_bytes'],d['image']['sha256'][:16],h,sep='\t')" >> $out
   done
  done
 done
 uptime >> $out.load
done
