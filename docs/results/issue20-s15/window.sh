#!/bin/bash
# Issue 20, session 15: acceptance 3 (two threads, paired) and acceptance 1 (one thread, paired with Embree) in one
# quiet window (both cores free). Usage: window.sh BIN OUTDIR
B=$1; O=$2; mkdir -p $O
stamp() { echo "== $1 $(date -u +%H:%M:%S) load $(cut -d' ' -f1-3 /proc/loadavg)"; }
stamp start
for i in 1 2; do
  $B run --engines embree,bvh4,bvh8,grid --scenes standard --threads 2 --repeat 1 --paired-threads 5 --no-check \
    --out $O/threads-$i > $O/threads-$i.log 2>&1; stamp "done threads-$i rc $?"
done
$B run --engines embree,bvh4,bvh8 --scenes standard --threads 1 --repeat 5 --paired 7 --no-check \
  --out $O/one-thread > $O/one-thread.log 2>&1; stamp "done one-thread rc $?"
stamp end
