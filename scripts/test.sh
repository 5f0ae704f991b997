#!/usr/bin/env bash
# rtbench's tests, from a fresh clone: set up (libclang, Embree; Chromium, for the test that loads the nightly
# dashboard headless), then the whole workspace's tests.
# Usage: bash scripts/test.sh [extra cargo test arguments]
#        RTBENCH_FUZZ_N=1000000 bash scripts/test.sh   also runs the large fuzz of the harness's readers (minutes)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
[ -x "$HOME/.cargo/bin/cargo" ] && export PATH="$HOME/.cargo/bin:$PATH"
command -v cargo >/dev/null || { echo "test.sh: error: cargo not found (install Rust with rustup)" >&2; exit 1; }
bash scripts/setup.sh
if ! command -v chromium >/dev/null; then
    SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
    echo "test.sh: installing chromium with apt-get (the nightly dashboard's test loads it headless)"
    $SUDO env DEBIAN_FRONTEND=noninteractive apt-get update -qq >/dev/null
    $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends chromium >/dev/null
fi
cargo test --workspace "$@"
# A test that must run in a process of its own (see its comment in harness/src/reproduce/invocation.rs).
cargo test -p rtbench --bin rtbench -- --ignored --exact reproduce::invocation::tests::an_invocation_keeps_its_cpu_and_wall_seconds
# The large fuzz (harness/src/fuzz.rs, fuzz_at_scale), only when asked for with RTBENCH_FUZZ_N.
if [ -n "${RTBENCH_FUZZ_N:-}" ]; then
    cargo test --release -p rtbench --bin rtbench -- --ignored --exact fuzz::fuzz_at_scale
fi
