#!/bin/bash
# Issue 20 acceptance 3, session 14 helper: the quiet window (both cores free). Paired one- and two-thread
# traces (`run-one --threads 2 --paired-threads 5`, session 12's protocol) with each pool thread's scheduler
# accounting and every band's CPU per render (RTBENCH_SCHED=bands), then the same with the pool's threads pinned
# one per CPU (RTBENCH_PIN_THREADS=1). Usage: window.sh BIN OUTDIR
B=$1; O=$2; Q=${QUIET_FILE:?set QUIET_FILE to the file that marks the quiet window}; mkdir -p $O
stamp() { echo "$1 $(date -u +%H:%M:%S) load $(cut -d' ' -f1-3 /proc/loadavg) quiet $(test -e $Q && echo yes || echo no) $(grep '^cpu ' /proc/stat)"; }
one() { # tag engine scene sf [env...]
  local tag=$1 e=$2 n=$3 sf=$4; shift 4
  test -e $Q || { stamp "window closed before $tag $e $n$sf"; exit 1; }
  env RTBENCH_SCHED=bands "$@" $B run-one --scene $n --sf $sf --engine $e --threads 2 --repeat 1 --size 512 \
    --no-check --paired-threads 5 > $O/$tag-$e-$n$sf.json 2> $O/$tag-$e-$n$sf.sched
  stamp "done $tag $e $n$sf rc $?"
}
stamp start
ps -eo pid,psr,pcpu,stat,comm --sort=-pcpu | head -6
for r in a b; do
  for sc in "balls 4" "rings 7" "gears 4" "mount 6"; do
    for e in embree bvh8; do one $r-free $e $sc; one $r-pin $e $sc RTBENCH_PIN_THREADS=1; done
  done
done
for sc in "teapot 12" "tetra 6" "tree 11"; do for e in embree bvh8; do one a-free $e $sc; one a-pin $e $sc RTBENCH_PIN_THREADS=1; done; done
for sc in "balls 4" "rings 7" "gears 4" "mount 6"; do one a-free bvh4 $sc; one a-pin bvh4 $sc RTBENCH_PIN_THREADS=1; done
stamp end
