#!/bin/bash
# OUT=DIR sum.sh TAG: M instructions per entry point (bvh8 eye halved), from cg.sh's profiles in $OUT
OUT=${OUT:?set OUT to the directory cg.sh wrote}
for S in gears tetra; do
  f=$OUT/cg.$1.$S
  callgrind_annotate --inclusive=yes $f 2>/dev/null | grep -E "x86::(avx8|fma4)_(closest|any)_impl \[" | awk -v S=$S '{c=$1; gsub(",","",c); n=$NF; sub(/.*x86::/,"",$0); split($0,a," "); name=a[1]; if (name ~ /avx8_closest/) c=c/2; printf "%s %-20s %8.2f M\n", S, name, c/1e6}'
done
