#!/bin/bash
# Issue 20 acceptance 3, session 14 helper: the quiet window (both cores free). Paired one/two-thread
# traces of Embree and bvh8 on the four scenes where Embree's threads were off a CPU, with each pool
# thread's scheduler accounting per render (RTBENCH_SCHED=1). Usage: window.sh BIN OUTDIR
B=$1; O=$2; mkdir -p $O
stamp() { echo "$1 $(date -u +%H:%M:%S) load $(cut -d' ' -f1-3 /proc/loadavg) quiet $(test -e /work/runs/QUIET && echo yes || echo no) cpu $(grep '^cpu ' /proc/stat)"; }
stamp start
for sc in balls:4 rings:7 gears:4 mount:6; do
  for e in embree bvh8; do
    test -e /work/runs/QUIET || { stamp "window closed before $e $sc"; exit 1; }
    n=${sc%:*}; sf=${sc#*:}
    echo "== $e $n$sf"
    RTBENCH_SCHED=1 $B run-one --scene $n --sf $sf --engine $e --threads 2 --repeat 1 --size 512 --no-check --paired-threads 5 \
      > $O/$e-$n$sf.json 2> $O/$e-$n$sf.sched
    stamp "done $e $n$sf rc $?"
  done
done
stamp end
