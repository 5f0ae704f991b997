#!/bin/bash
# usage: OUT=DIR cg.sh BIN TAG  -> callgrind for gears and tetra, bvh8 + bvh4 single, profiles in $OUT
BIN=$1; TAG=$2
OUT=${OUT:?set OUT to a directory for the profiles (e.g. OUT=$(mktemp -d))}
cd "$(git rev-parse --show-toplevel)"
for S in gears tetra; do
  taskset -c 1 valgrind --tool=callgrind --dump-instr=yes --callgrind-out-file=$OUT/cg.$TAG.$S $BIN $S --once --size 256 --engines "bvh4 single" > $OUT/cg.$TAG.$S.log 2>&1
  callgrind_annotate --inclusive=yes $OUT/cg.$TAG.$S 2>/dev/null | grep -E "closest_impl|any_impl|rtcIntersect1|rtcOccluded1" | grep -v "::{{closure}}" > $OUT/cg.$TAG.$S.sum
done
