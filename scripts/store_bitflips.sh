#!/usr/bin/env bash
# Random bit flips in a scene store's files: each flip is made in a fresh
# copy of the store, which is then rendered out of core. Every flip must be refused (exit 2); none
# may render a different image with exit 0.
# Usage: bash scripts/store_bitflips.sh [FLIPS=200] [SEED=14] [RTBENCH=target/release/rtbench]
# Prints one line of totals: flips, refused (exit 2), same image (exit 0), different image
# (exit 0), panics (101), signals (>128), hangs (timeout), other; exits 1 unless all were refused.
set -uo pipefail
FLIPS=${1:-200}
SEED=${2:-14}
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
B=${3:-$ROOT/target/release/rtbench}
[ -x "$B" ] || { echo "store_bitflips.sh: $B not built (cargo build --release -p rtbench)" >&2; exit 2; }
WORK=$(mktemp -d -t rtbench-bitflips.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
RANDOM=$SEED

"$B" scene store tree --sf 2 -o "$WORK/store" >/dev/null 2>&1 || { echo "cannot write the store" >&2; exit 2; }
render() { # store → prints the image sha256, returns rtbench's status
    local out rc
    out=$(timeout 60 "$B" render --scene "$1" --engine breadth-first --size 32 --set memory=1MiB --json 2>"$WORK/err")
    rc=$?
    printf '%s' "$out" | grep -o '"sha256": *"[0-9a-f]*"' | grep -o '[0-9a-f]\{64\}'
    return $rc
}
BASE=$(render "$WORK/store") || { echo "the unflipped store does not render" >&2; exit 2; }

refused=0 same=0 different=0 panics=0 signals=0 hangs=0 other=0
files=(header.json bbox.bin geometry.bin materials.bin)
for ((i = 0; i < FLIPS; i++)); do
    rm -rf "$WORK/flip"
    cp -r "$WORK/store" "$WORK/flip"
    f="$WORK/flip/${files[$((i % 4))]}"
    size=$(stat -c %s "$f")
    off=$(( (RANDOM * 32768 + RANDOM) % size ))
    bit=$((RANDOM % 8))
    byte=$(od -An -tu1 -j "$off" -N1 "$f" | tr -d ' ')
    printf "$(printf '\\%03o' $((byte ^ (1 << bit))))" | dd of="$f" bs=1 seek="$off" conv=notrunc status=none
    sha=$(render "$WORK/flip")
    rc=$?
    case $rc in
        2) refused=$((refused + 1)) ;;
        0) if [ "$sha" = "$BASE" ]; then same=$((same + 1)); else different=$((different + 1)); fi
           echo "accepted: ${files[$((i % 4))]} byte $off bit $bit (image $([ "$sha" = "$BASE" ] && echo same || echo different))" >&2 ;;
        101) panics=$((panics + 1)); echo "panic: ${files[$((i % 4))]} byte $off bit $bit" >&2 ;;
        124) hangs=$((hangs + 1)); echo "hang: ${files[$((i % 4))]} byte $off bit $bit" >&2 ;;
        *) if [ "$rc" -gt 128 ]; then signals=$((signals + 1)); else other=$((other + 1)); fi
           echo "exit $rc: ${files[$((i % 4))]} byte $off bit $bit: $(head -c 200 "$WORK/err")" >&2 ;;
    esac
done
echo "flips $FLIPS refused $refused same_image_exit0 $same different_image_exit0 $different panics $panics signals $signals hangs $hangs other $other"
[ "$refused" -eq "$FLIPS" ]
