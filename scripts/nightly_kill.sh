#!/usr/bin/env bash
# The nightly history survives kill -9 and concurrent writers.
#
# 1. Until KILLS kills have landed: start `rtbench nightly` of a tiny suite on one history and
#    kill -9 it after a random delay spread over a whole night (the measuring, the comparison and
#    the write; a night that finished before its delay is counted apart and tried again). After
#    every kill `rtbench history check` must answer integrity_check ok, and every night in the
#    history must hold all of a whole night's metrics (no half-written night).
# 2. PAIRS times: start two `rtbench nightly` on one history at the same moment; both must exit 0
#    and both nights must land.
#
# Usage: bash scripts/nightly_kill.sh [KILLS=20] [PAIRS=5] [SEED=16] [RTBENCH=target/release/rtbench]
# Prints one line per kill and per pair, then totals; exits 1 unless every check held.
set -uo pipefail
KILLS=${1:-20}
PAIRS=${2:-5}
SEED=${3:-16}
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
B=${4:-$ROOT/target/release/rtbench}
[ -x "$B" ] || { echo "nightly_kill.sh: $B not built (cargo build --release -p rtbench)" >&2; exit 2; }
command -v python3 >/dev/null || { echo "nightly_kill.sh: needs python3 (to read history list --json)" >&2; exit 2; }
WORK=$(mktemp -d -t rtbench-nightly-kill.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
RANDOM=$SEED
DB=$WORK/h.sqlite
cat >"$WORK/suite.toml" <<'EOF'
name = "kill"
engines = ["embree", "grid", "bvh4"]
scenes = ["tetra", "balls"]
sf = [1]
repeats = 3
paired = 2
size = 24
gate = ["counters"]
EOF

night() { "$B" nightly --suite "$WORK/suite.toml" --db "$DB" --note "$1" >"$WORK/out" 2>"$WORK/err"; }
# nights, whole nights (every one holding M metrics), as "N W"
census() {
    "$B" history list --db "$DB" --json | python3 -c '
import json, sys
runs = json.load(sys.stdin); m = int(sys.argv[1])
print(len(runs), sum(1 for r in runs if r["metrics"] == m))' "$1"
}

t0=$(date +%s%N)
night "whole" || { echo "nightly_kill.sh: the first night failed: $(tail -1 "$WORK/err")" >&2; exit 2; }
NIGHT_MS=$((($(date +%s%N) - t0) / 1000000))
M=$("$B" history list --db "$DB" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)[0]["metrics"])')
echo "a whole night: $M metrics, ${NIGHT_MS} ms"

ok=0 bad=0 finished=0 killed=0
for ((i = 1; killed < KILLS && i <= 3 * KILLS; i++)); do
    # A delay from 1% to 105% of a night: the last ones catch the comparison and the write.
    delay=$((NIGHT_MS * (1 + RANDOM % 105) / 100))
    "$B" nightly --suite "$WORK/suite.toml" --db "$DB" --note "kill $i" >/dev/null 2>&1 &
    pid=$!
    sleep "$(printf '%d.%03d' $((delay / 1000)) $((delay % 1000)))"
    if kill -9 "$pid" 2>/dev/null; then what="killed at ${delay} ms"; killed=$((killed + 1)); else what="finished before ${delay} ms"; finished=$((finished + 1)); fi
    wait "$pid" 2>/dev/null
    check=$("$B" history check --db "$DB" 2>&1)
    read -r n w < <(census "$M")
    if [[ $check == *"integrity_check ok"* && $n == "$w" ]]; then
        ok=$((ok + 1)); verdict=ok
    else
        bad=$((bad + 1)); verdict="BAD ($check; $n nights, $w whole)"
    fi
    echo "kill $i: $what: $verdict; $n nights"
done

pairs_ok=0
for ((i = 1; i <= PAIRS; i++)); do
    read -r before _ < <(census "$M")
    "$B" nightly --suite "$WORK/suite.toml" --db "$DB" --note "pair $i a" >/dev/null 2>"$WORK/a.err" &
    a=$!
    "$B" nightly --suite "$WORK/suite.toml" --db "$DB" --note "pair $i b" >/dev/null 2>"$WORK/b.err" &
    b=$!
    wait "$a"; ra=$?
    wait "$b"; rb=$?
    read -r after w < <(census "$M")
    if [[ $ra == 0 && $rb == 0 && $after == $((before + 2)) && $w == "$after" ]]; then
        pairs_ok=$((pairs_ok + 1)); verdict=ok
    else
        verdict="BAD (exit $ra and $rb; $before → $after nights, $w whole; $(tail -1 "$WORK/a.err") $(tail -1 "$WORK/b.err"))"
    fi
    echo "pair $i: $verdict; $before → $after nights"
done
echo "kills: $killed landed ($finished nights finished before their delay), history whole after $ok tries, not after $bad; concurrent pairs: $pairs_ok of $PAIRS landed both"
[[ $bad == 0 && $killed == "$KILLS" && $pairs_ok == "$PAIRS" ]]
