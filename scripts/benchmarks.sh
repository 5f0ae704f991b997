#!/usr/bin/env bash
# Regenerates every table of docs/benchmarks.md: runs the commands below into OUT (default out/benchmarks), then
# prints the tables as Markdown (scripts/benchmarks.py) with the date, commit and machine of each.
# Usage: bash scripts/benchmarks.sh [OUT] [TABLE…]
#   TABLE: grid ooc build speed goals wide tinybvh grid-then in-core two-threads (default: all ten)
# The speed run also gives the memory table. grid-then runs the grid of commit cd8e501, the main the performance
# targets were set against: RTBENCH_THEN names its rtbench binary, or the script builds it in OUT/then-src.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
[ -x "$HOME/.cargo/bin/cargo" ] && export PATH="$HOME/.cargo/bin:$PATH"
OUT="${1:-out/benchmarks}"
shift || true
TABLES="${*:-grid ooc build speed goals wide tinybvh grid-then in-core two-threads}"
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
        wide)
            # Target: bvh8 at least 1.1x and bvh4 at least 1.0x Embree's speed (512², the SPD standard).
            say "wide: $RT run --engines embree,bvh4,bvh8 --scenes standard --threads 1 --repeat 3 --paired 9 --out $OUT/wide"
            "$RT" run --engines embree,bvh4,bvh8 --scenes standard --threads 1 --repeat 3 --paired 9 --out "$OUT/wide" --resume
            ;;
        tinybvh)
            # Target: bvh8 at least as fast as tinybvh's fastest layout on tessellated balls4, gears4 and tree10.
            E="embree,bvh8,tinybvh:layout=bvh8_cpu,tinybvh:layout=bvh4_cpu,tinybvh:layout=cwbvh,tinybvh:layout=bvh"
            say "tinybvh: $RT run --engines $E --scenes balls,gears --sf 4 --tessellate --threads 1 --repeat 3 --paired 9 --out $OUT/tinybvh (and tree --sf 10)"
            "$RT" run --engines "$E" --scenes balls,gears --sf 4 --tessellate --threads 1 --repeat 3 --paired 9 \
                --out "$OUT/tinybvh" --resume
            "$RT" run --engines "$E" --scenes tree --sf 10 --tessellate --threads 1 --repeat 3 --paired 9 \
                --out "$OUT/tinybvh" --resume
            ;;
        grid-then)
            # Target: the grid at least 1.3x faster per ray than cd8e501's, at the same counters. Each binary times
            # its grid in pairs with Embree; that binary has no rounds, so it runs six processes of 3 pairs.
            THEN="${RTBENCH_THEN:-}"
            if [ -z "$THEN" ]; then
                if [ ! -d "$OUT/then-src" ]; then
                    mkdir -p "$OUT/then-src"
                    git archive cd8e501 | tar -x -C "$OUT/then-src"
                fi
                cargo build --release -p rtbench --manifest-path "$OUT/then-src/Cargo.toml"
                THEN="$OUT/then-src/target/release/rtbench"
            fi
            say "grid-then: $RT run --engines embree,grid --scenes standard --threads 1 --repeat 3 --paired 9 --out $OUT/grid-now"
            "$RT" run --engines embree,grid --scenes standard --threads 1 --repeat 3 --paired 9 --out "$OUT/grid-now" --resume
            for r in 1 2 3 4 5 6; do
                say "grid-then: $THEN run --engines embree,grid --scenes standard --threads 1 --repeat 1 --paired 3 --out $OUT/grid-then-$r"
                "$THEN" run --engines embree,grid --scenes standard --threads 1 --repeat 1 --paired 3 --out "$OUT/grid-then-$r" --resume
            done
            ;;
        in-core)
            # Target: breadth-first at its defaults in memory within 2x bvh8's peak RSS and 1.5x the grid's time.
            say "in-core: $RT run --engines embree,grid,bvh8,breadth-first --scenes standard --threads 1 --repeat 3 --paired 5 --out $OUT/in-core"
            "$RT" run --engines embree,grid,bvh8,breadth-first --scenes standard --threads 1 --repeat 3 --paired 5 \
                --out "$OUT/in-core" --resume
            ;;
        two-threads)
            # Target: two threads at least 1.8x one thread, every engine and scene: the same structure traced at one
            # thread and at two, back to back, 5 pairs or more over 3 rounds and up to 5 while wider than ±2 %.
            say "two-threads: $RT run --engines all --scenes standard --size 256 --threads 2 --paired-threads 5 --paired 0 --repeat 3 --max-rounds 5 --no-check --out $OUT/two-threads"
            "$RT" run --engines all --scenes standard --size 256 --threads 2 --paired-threads 5 --paired 0 --repeat 3 \
                --max-rounds 5 --no-check --out "$OUT/two-threads" --resume
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
        *) echo "benchmarks.sh: unknown table '$t' (grid ooc build speed goals wide tinybvh grid-then in-core two-threads)" >&2
           exit 2 ;;
    esac
done
python3 scripts/benchmarks.py "$OUT"
