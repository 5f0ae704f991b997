#!/usr/bin/env bash
# rtbench's tests, from a fresh clone: set up (libclang, Embree), then the whole workspace's tests.
# Usage: bash scripts/test.sh [extra cargo test arguments]
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
[ -x "$HOME/.cargo/bin/cargo" ] && export PATH="$HOME/.cargo/bin:$PATH"
command -v cargo >/dev/null || { echo "test.sh: error: cargo not found (install Rust with rustup)" >&2; exit 1; }
bash scripts/setup.sh
cargo test --workspace "$@"
