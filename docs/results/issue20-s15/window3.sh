#!/bin/bash
# Issue 20, session 15, quiet window 3 (both cores free), on the final engine code: every acceptance item once more.
# Usage: window3.sh RTBENCH PACKETS_BENCH BUILDS_BENCH OUTDIR
B=$1; P=$2; E=$3; O=$4; D=$(dirname $0); mkdir -p $O
stamp() { echo "== $1 $(date -u +%H:%M:%S) load $(cut -d' ' -f1-3 /proc/loadavg)"; }
stamp start
for i in 1 2; do
  $B run --engines embree,bvh4,bvh8,grid --scenes standard --threads 2 --repeat 1 --paired-threads 5 --no-check \
    --out $O/threads-$i > $O/threads-$i.log 2>&1; stamp "done threads-$i rc $?"
done
$B run --engines embree,bvh4,bvh8 --scenes standard --threads 1 --repeat 5 --paired 7 --no-check \
  --out $O/one-thread > $O/one-thread.log 2>&1; stamp "done one-thread rc $?"
$P gears:4 tree:10 balls:4 --tessellate 3 --size 512 --pairs 13 --engines "embree single,bvh4 single,bvh8 single"; stamp "done tessellated rc $?"
$P gears tetra balls --size 512 --pairs 21 --engines "bvh8,embree"; stamp "done packets rc $?"
$E balls --rounds 9; stamp "done builds rc $?"
python3 $D/a5.py $B $O/a5.jsonl 5; stamp "done a5 rc $?"
stamp end
