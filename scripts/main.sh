#!/usr/bin/env bash
# rtbench's main job, from a fresh clone: set up (libclang, Embree), build, then the quick run: every available
# engine × the seven standard SPD scenes at their standard size factors, one thread, each run cross-checked
# against Embree (the in-memory engines 3 repeats; the out-of-core breadth-first engine and the object-space
# machine simulation, which take seconds a scene, one); then the report (tables and plots) and the SPD
# ray-statistics table.
# Results: OUT_DIR/results.jsonl, OUT_DIR/report.md, OUT_DIR/report.html, OUT_DIR/plots/, OUT_DIR/spd-stats.md.
# Usage: bash scripts/main.sh [OUT_DIR]     (default out/quick; an existing OUT_DIR is resumed)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
[ -x "$HOME/.cargo/bin/cargo" ] && export PATH="$HOME/.cargo/bin:$PATH"
command -v cargo >/dev/null || { echo "main.sh: error: cargo not found (install Rust with rustup)" >&2; exit 1; }
OUT="${1:-out/quick}"
bash scripts/setup.sh
echo "main.sh: building rtbench (cargo's progress below; a first build takes minutes)"
cargo build --release -p rtbench
RT=./target/release/rtbench
$RT engines
$RT run --engines embree,grid,bvh2,bvh4,bvh8,obvhs --scenes standard --repeat 3 --threads 1 --out "$OUT" --resume
$RT run --engines breadth-first,object-space --scenes standard --repeat 1 --threads 1 --out "$OUT" --resume
$RT report "$OUT"
$RT reproduce spd-stats --engines embree --out "$OUT" >/dev/null
echo
sed -n '/^## /,$p' "$OUT/report.md" | sed '/^## Plots/,$d'
echo
cat "$OUT/spd-stats.md"
echo
echo "main.sh: report in $OUT/report.md and $OUT/report.html"
