#!/bin/bash
# cg.sh BIN TAG SCENE ENGINES [extra bench args]: callgrind of the packets bench (--once, 256²) into $OUT
# (a directory the caller makes); TAG-SCENE.txt keeps the entry points' inclusive counts (read by sum.py).
BIN=$1; TAG=$2; S=$3; E=$4; shift 4
taskset -c 1 valgrind --tool=callgrind --callgrind-out-file=$OUT/$TAG-$S.cg $BIN $S --once --size 256 --engines "$E" "$@" > $OUT/$TAG-$S.log 2>&1
callgrind_annotate --inclusive=yes $OUT/$TAG-$S.cg 2>/dev/null | grep -E "closest_impl|any_impl|rtcIntersect|rtcOccluded" > $OUT/$TAG-$S.txt
