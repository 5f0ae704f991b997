#!/usr/bin/env bash
# The nightly regression run: set up (Embree, libclang, valgrind), build, run the default suite
# (suites/nightly.toml) into the SQLite history, and write the night's Markdown summary and the dashboard.
# Exits 1 only when a gated metric regressed (the summary names it), 2 on bad input.
#   Results: OUT/run-<UTC time>/ (results.jsonl, nightly.md, dashboard/index.html); history: DB.
#   In a CI job with $GITHUB_STEP_SUMMARY set, the summary is appended to the job page.
# Usage: bash scripts/nightly.sh [DB] [OUT]     (defaults out/nightly/history.sqlite, out/nightly)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
[ -x "$HOME/.cargo/bin/cargo" ] && export PATH="$HOME/.cargo/bin:$PATH"
command -v cargo >/dev/null || { echo "nightly.sh: error: cargo not found (install Rust with rustup)" >&2; exit 2; }
OUT="${2:-out/nightly}"
DB="${1:-$OUT/history.sqlite}"
bash scripts/setup.sh
if ! command -v valgrind >/dev/null; then
    SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
    echo "nightly.sh: installing valgrind with apt-get (instruction counts)"
    $SUDO env DEBIAN_FRONTEND=noninteractive apt-get update -qq >/dev/null
    $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends valgrind >/dev/null
fi
# Build with cargo's progress on the terminal (a first build takes minutes): the binary, then the suite's
# criterion benches, which `rtbench nightly` would otherwise build behind its own quiet `cargo bench`.
echo "nightly.sh: building rtbench and the criterion benches (cargo's progress below)"
cargo build --release -p rtbench
BENCH="$(sed -n 's/^bench *= *"\(.*\)"/\1/p' suites/nightly.toml | head -n 1)"
cargo bench -p rtbench-engines ${BENCH:+--bench "$BENCH"} --no-run
echo "nightly.sh: running suites/nightly.toml (each run's progress below)"
mkdir -p "$OUT" "$(dirname "$DB")"
RUN="$OUT/run-$(date -u +%Y%m%dT%H%M%SZ)"
rc=0
./target/release/rtbench nightly --suite suites/nightly.toml --db "$DB" --out "$RUN" >/dev/null || rc=$?
if [ -f "$RUN/nightly.md" ]; then
    cat "$RUN/nightly.md"
    [ -n "${GITHUB_STEP_SUMMARY:-}" ] && cat "$RUN/nightly.md" >> "$GITHUB_STEP_SUMMARY"
fi
echo "nightly.sh: history $DB, summary $RUN/nightly.md, dashboard $RUN/dashboard/index.html (exit $rc)"
exit $rc
