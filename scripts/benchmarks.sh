#!/usr/bin/env bash
# Regenerates every table of docs/benchmarks.md: runs the commands below into OUT (default out/benchmarks), then
# prints the tables as Markdown (scripts/benchmarks.py) with the date, commit and machine of each.
# Usage: bash scripts/benchmarks.sh [OUT] [TABLE…]     TABLE: grid ooc threads build speed goals (default: all six)
# The speed run also gives the memory table.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
[ -x "$HOME/.cargo/bin/cargo" ] && export PATH="$HOME/.cargo/bin:$PATH"
OUT="${1:-out/benchmarks}"
shift || true
TABLES="${*:-grid ooc threads build speed goals}"
RT="${RTBENCH:-./target/release/rtbench}"
if [ -z "${RTBENCH:-}" ]; then
    bash scripts/setup.sh
    echo "benchmarks.sh: building rtbench (cargo's progress below)"
    cargo build --release -p rtbench
fi
mkdir -p "$OUT"
say() { echo "benchmarks.sh: $*" >&2; }

for t in $TABLES; do
    case "$t" in
        speed)
            # Speed against Embree and the peers, memory, build time: one thread, 256², 9 engine/Embree pairs
            # over 3 rounds and more for a run still wider than ±2 % (processes minutes apart: the interval is over the rounds; 256² keeps the table
            # within an hour on a shared 2-core machine; 512² is the SPD standard).
            say "speed: $RT run --engines embree,grid,bvh2,bvh4,bvh8,obvhs --scenes standard --size 256 --repeat 3 --paired 9 --out $OUT/speed"
            "$RT" run --engines embree,grid,bvh2,bvh4,bvh8,obvhs --scenes standard --size 256 --repeat 3 --paired 9 \
                --out "$OUT/speed" --resume
            ;;
        threads)
            # Thread scaling: the same structure traced at one and at two threads, 9 pairs over 3 rounds and more while wide.
            say "threads: $RT run --engines embree,bvh8 --scenes balls,gears,tree --size 256 --threads 2 --paired-threads 9 --repeat 3 --no-check --out $OUT/threads"
            "$RT" run --engines embree,bvh8 --scenes balls,gears,tree --size 256 --threads 2 --paired-threads 9 \
                --repeat 3 --no-check --out "$OUT/threads" --resume
            ;;
        build)
            # Build time: 7 builds of every structure over 3 rounds (3 processes), 3 more in each further round, at an image of 16² so
            # that tracing costs nothing.
            say "build: $RT run --engines embree,grid,bvh2,bvh4,bvh8,obvhs --scenes standard --size 16 --repeat 7 --no-check --out $OUT/build"
            "$RT" run --engines embree,grid,bvh2,bvh4,bvh8,obvhs --scenes standard --size 16 --repeat 7 --no-check \
                --out "$OUT/build" --resume
            ;;
        grid)
            # The grid's exact counters under the Rayshade-style presets (seed 000's rss and rss-r).
            say "grid: $RT run --engines grid:preset=rss,grid:preset=rss-r --scenes standard --size 256 --repeat 1 --no-check --out $OUT/grid"
            "$RT" run --engines grid:preset=rss,grid:preset=rss-r --scenes standard --size 256 --repeat 1 --no-check \
                --out "$OUT/grid" --resume
            ;;
        ooc)
            # Out of core: mount8 (131,076 objects) from a scene store with a small memory budget, against the
            # same engine in memory and the in-memory grid.
            [ -d "$OUT/ooc/mount8" ] || { mkdir -p "$OUT/ooc"; "$RT" scene store mount --sf 8 -o "$OUT/ooc/mount8" >/dev/null; }
            for m in 8MiB 32MiB; do
                say "ooc: $RT render --scene $OUT/ooc/mount8 --engine breadth-first --set memory=$m --threads 1 --size 256 --json"
                "$RT" render --scene "$OUT/ooc/mount8" --engine breadth-first --set memory=$m --threads 1 --size 256 --json \
                    > "$OUT/ooc/store-$m.json"
            done
            say "ooc: $RT render --scene mount --sf 8 --engine breadth-first|grid --threads 1 --size 256 --json"
            "$RT" render --scene mount --sf 8 --engine breadth-first --threads 1 --size 256 --json > "$OUT/ooc/memory-bf.json"
            "$RT" render --scene mount --sf 8 --engine grid --threads 1 --size 256 --json > "$OUT/ooc/memory-grid.json"
            ;;
        goals)
            # Our own goals for the engines, measured beside 001's SIMD claim (kimura-simd's result of record is the
            # same command's document): the engines at their defaults against Embree and obvhs, and the ablation.
            say "goals: $RT reproduce kimura-simd --out $OUT/goals"
            "$RT" reproduce kimura-simd --out "$OUT/goals"
            ;;
        *) echo "benchmarks.sh: unknown table '$t' (speed, threads, build, grid, ooc, goals)" >&2; exit 2 ;;
    esac
done
python3 scripts/benchmarks.py "$OUT"
