#!/bin/bash
# Issue 20 acceptance 3, session 14 helper, second part of the quiet window: session 12's acceptance run
# (embree, bvh4, bvh8 on the seven scenes, two threads, 5 pairs) with the pool's threads free and pinned one
# per CPU (RTBENCH_PIN_THREADS=1), alternating, as long as the window lasts. Usage: window2.sh BIN OUTDIR
B=$1; O=$2; Q=${QUIET_FILE:?set QUIET_FILE to the file that marks the quiet window}; mkdir -p $O
stamp() { echo "$1 $(date -u +%H:%M:%S) load $(cut -d' ' -f1-3 /proc/loadavg) quiet $(test -e $Q && echo yes || echo no) $(grep '^cpu ' /proc/stat)"; }
stamp start
for sc in balls gears mount rings teapot tetra tree; do
  for mode in free pin; do
    test -e $Q || { stamp "window closed before $mode $sc"; exit 1; }
    if [ $mode = pin ]; then P="RTBENCH_PIN_THREADS=1"; else P="RTBENCH_NOTHING=1"; fi
    env $P $B run --engines embree,bvh4,bvh8 --scenes $sc --threads 2 --repeat 1 --paired-threads 5 --no-check \
      --out $O/$mode-$sc > $O/$mode-$sc.log 2>&1
    stamp "done $mode $sc rc $?"
  done
done
stamp end
