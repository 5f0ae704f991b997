#!/bin/bash
# mnemonics.sh CG_A BIN_A CG_B BIN_B FUNCTION: instructions executed per mnemonic in FUNCTION (e.g. fma4_any_impl),
# profile A against profile B (callgrind --dump-instr=yes), the mnemonics that changed by more than 200,000
cd "$(git rev-parse --show-toplevel)"
count() { python3 docs/results/issue20-s10a/annot.py "$1" "$2" "$3" 1 | awk 'NR>1 {c=$1; gsub(",","",c); n[$3]+=c} END {for (m in n) print m, n[m]}' | sort; }
join -a1 -a2 -e0 -o 0,1.2,2.2 <(count "$1" "$2" "$5") <(count "$3" "$4" "$5") |
  awk '{d=$3-$2; if (d*d > 4e10) printf "%-14s %12d %12d %+12d\n", $1, $2, $3, d}' | sort -k4 -n
