#!/bin/bash
# usage: OUT=DIR cg.sh BENCH TAG -> callgrind of the packets bench (--once, 256²) on gears4, teapot12 and
# balls4 tessellated (RES 3): bvh8, bvh4 and Embree single rays; M instructions per entry point (inclusive;
# bvh8's eye trace runs twice in the bench and is halved) on stdout; profiles in $OUT.
BENCH=$1; TAG=$2
OUT=${OUT:?set OUT to a directory for the profiles (e.g. OUT=$(mktemp -d))}
cd "$(git rev-parse --show-toplevel)"
for S in gears:4 teapot:12 "balls:4 --tessellate 3"; do
  n=$(echo $S | tr ': ' '__' | cut -c1-12)
  taskset -c 1 valgrind --tool=callgrind --dump-instr=yes --callgrind-out-file=$OUT/cg.$TAG.$n $BENCH $S --once --size 256 --engines "bvh4 single,embree single" > $OUT/cg.$TAG.$n.log 2>&1
  callgrind_annotate --inclusive=yes --threshold=100 $OUT/cg.$TAG.$n 2>/dev/null | grep -E "x86::(fma4|avx8)_(closest|any)_impl \[|rtc(Intersect|Occluded)1 \[" | awk -v T=$TAG -v S=$n '{c=$1; gsub(",","",c); f=$0; sub(/.*(x86::|\?\?\?:)/,"",f); sub(/ \[.*/,"",f); if (f ~ /avx8_closest/) c=c/2; printf "%s %s %-20s %8.2f M\n", T, S, f, c/1e6}'
done
