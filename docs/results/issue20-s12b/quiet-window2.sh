#!/bin/bash
# Helper b (issue 20, session 12), quiet window 2 (15:25, after this helper's last commit): the tree
# setting sah_block=8 against the default, paired in one process, on the all-triangle scenes. One
# thread pinned to CPU 1; main's binaries built beforehand; writes only under
# $W/scratch/window2/ and to stdout. ≤ ~5.5 min (each step under a timeout).
W=$(git rev-parse --show-toplevel)
O=$W/scratch/window2
cd $W
echo "start $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)"
timeout 100 taskset -c 1 $W/target/rtbench-base run --engines embree,bvh4,bvh4:sah_block=8,bvh8,bvh8:sah_block=8 --scenes gears,teapot,tetra --threads 1 --repeat 3 --paired 7 --no-check --out $O/ab-std 2>&1 | tail -1
python3 $W/docs/results/issue20-s12b/ratios_var.py $O/ab-std
echo "std done $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)"
timeout 130 taskset -c 1 $W/target/rtbench-base run --engines embree,bvh4,bvh4:sah_block=8,bvh8,bvh8:sah_block=8 --scenes balls,gears --tessellate 3 --threads 1 --repeat 3 --paired 7 --no-check --out $O/ab-tess 2>&1 | tail -1
python3 $W/docs/results/issue20-s12b/ratios_var.py $O/ab-tess
echo "tess done $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)"
timeout 45 taskset -c 1 $W/target/packets-base balls:4 gears:4 --tessellate 3 --size 512 --pairs 7 --engines "embree single,bvh4 single" 2>&1 | grep -E "sf|speed"
timeout 45 taskset -c 1 $W/target/packets-base balls:4 gears:4 --tessellate 3 --size 512 --pairs 7 --engines "embree single,bvh4 single" --set-single sah_block=8 2>&1 | grep -E "sf|speed"
echo "end $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)"
