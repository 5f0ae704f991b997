#!/bin/bash
# Issue 20, session 15, quiet window 3 (both cores free), on the final engine code: every acceptance item once more
# (window.sh's two-thread and one-thread runs, then the rest). Usage: window3.sh RTBENCH PACKETS_BENCH BUILDS_BENCH OUTDIR
# window3.out was printed by an earlier copy of this script with window.sh's lines inline; the commands are the same.
B=$1; P=$2; E=$3; O=$4; D=$(dirname $0); mkdir -p $O
stamp() { echo "== $1 $(date -u +%H:%M:%S) load $(cut -d' ' -f1-3 /proc/loadavg)"; }
$D/window.sh $B $O
$P gears:4 tree:10 balls:4 --tessellate 3 --size 512 --pairs 13 --engines "embree single,bvh4 single,bvh8 single"; stamp "done tessellated rc $?"
$P gears tetra balls --size 512 --pairs 21 --engines "bvh8,embree"; stamp "done packets rc $?"
$E balls --rounds 9; stamp "done builds rc $?"
python3 $D/a5.py $B $O/a5.jsonl 5; stamp "done a5 rc $?"
stamp end
