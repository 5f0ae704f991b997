#!/bin/bash
# usage: cg.sh BIN TAG  -> callgrind for gears and tetra, bvh8 + bvh4 single
BIN=$1; TAG=$2
cd "$(git rev-parse --show-toplevel)"
for S in gears tetra; do
  taskset -c 1 valgrind --tool=callgrind --dump-instr=yes --callgrind-out-file=/tmp/s10a/cg.$TAG.$S $BIN $S --once --size 256 --engines "bvh4 single" > /tmp/s10a/cg.$TAG.$S.log 2>&1
  callgrind_annotate --inclusive=yes /tmp/s10a/cg.$TAG.$S 2>/dev/null | grep -E "closest_impl|any_impl|rtcIntersect1|rtcOccluded1" | grep -v "::{{closure}}" > /tmp/s10a/cg.$TAG.$S.sum
done
