#!/bin/bash
# Helper b (issue 20, session 12), quiet window 1: acceptance 1 on main's code (this worktree's
# binaries, built before the window), one thread pinned to CPU 1; writes only under
# $W/scratch/window1/ and to stdout. ≤ ~5.9 min (each step under a timeout).
# target/rtbench-base: main's binary (commit 1327c78, no engine change on this branch); target/packets-base:
# the packets bench of this branch (engines/benches/packets.rs with --set-single and counters).
W=$(git rev-parse --show-toplevel)
O=$W/scratch/window1
cd $W
echo "start $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)"
timeout 212 taskset -c 1 $W/target/rtbench-base run --engines embree,bvh4,bvh8 --scenes standard --threads 1 --repeat 5 --paired 7 --no-check --out $O/run-std 2>&1 | tail -3
echo "std done $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)"
timeout 95 taskset -c 1 $W/target/packets-base gears:4 tree:10 balls:4 --tessellate 3 --size 512 --pairs 13 --engines "embree single,bvh4 single" 2>&1
echo "packets done $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)"
timeout 45 taskset -c 1 $W/target/packets-base balls:4 gears:4 --tessellate 3 --size 512 --pairs 7 --engines "embree single,bvh4 single" --set-single sah_block=8 2>&1
echo "end $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)"
