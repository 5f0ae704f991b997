#!/usr/bin/env bash
# rtbench's main job, from a fresh clone: set up (libclang, Embree), build, then trace the SPD workload on the
# seven standard scenes with every available engine and print the ray-statistics table against the published one.
# Results: out/quick/spd-stats.md, out/quick/spd-stats.json, out/quick/images/*.png.
# Usage: bash scripts/main.sh [OUT_DIR]
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
[ -x "$HOME/.cargo/bin/cargo" ] && export PATH="$HOME/.cargo/bin:$PATH"
command -v cargo >/dev/null || { echo "main.sh: error: cargo not found (install Rust with rustup)" >&2; exit 1; }
OUT="${1:-out/quick}"
bash scripts/setup.sh
cargo build --release -p rtbench --quiet
./target/release/rtbench engines
./target/release/rtbench reproduce spd-stats --out "$OUT"
