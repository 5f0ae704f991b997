#!/bin/bash
# Issue 20, session 15, quiet window 2 (both cores free): acceptance 1 for 001's tessellated primary rays,
# acceptance 2 (packets), acceptance 4 (builds), and acceptance 1's standard-scene run a second time.
# Usage: window2.sh RTBENCH PACKETS_BENCH BUILDS_BENCH OUTDIR
B=$1; P=$2; E=$3; O=$4; mkdir -p $O
stamp() { echo "== $1 $(date -u +%H:%M:%S) load $(cut -d' ' -f1-3 /proc/loadavg)"; }
stamp start
$P gears:4 tree:10 balls:4 --tessellate 3 --size 512 --pairs 13 --engines "embree single,bvh4 single,bvh8 single"; stamp "done tessellated rc $?"
$P gears tetra balls --size 512 --pairs 21 --engines "bvh8,embree"; stamp "done packets rc $?"
$E balls --rounds 5; stamp "done builds rc $?"
$B run --engines embree,bvh4,bvh8 --scenes standard --threads 1 --repeat 5 --paired 7 --no-check \
  --out $O/one-thread-2 > $O/one-thread-2.log 2>&1; stamp "done one-thread-2 rc $?"
stamp end
