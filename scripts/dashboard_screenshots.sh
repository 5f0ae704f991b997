#!/usr/bin/env bash
# The nightly dashboard's screenshots in docs/images/dashboard-*.png: a small history (five nights of a tiny suite,
# then two nights with a planted slowdown of grid (half its queries answered twice) and a planted counter change of bvh4, RTBENCH_PLANT), its
# dashboard with commit links, and headless-Chromium PNGs of it.
# Usage: bash scripts/dashboard_screenshots.sh [WORK_DIR]   (WORK_DIR: where the history and the page go; default a
# temporary folder, removed at the end). Needs chromium and valgrind (the suite counts instructions).
set -euo pipefail
cd "$(dirname "$0")/.."
command -v chromium >/dev/null || { echo "dashboard_screenshots.sh: error: chromium not found (apt-get install chromium)" >&2; exit 1; }
command -v valgrind >/dev/null || { echo "dashboard_screenshots.sh: error: valgrind not found (apt-get install valgrind)" >&2; exit 1; }
cargo build --release -p rtbench >&2
BIN=target/release/rtbench
if [ $# -ge 1 ]; then
    WORK=$1; mkdir -p "$WORK"
else
    WORK=$(mktemp -d); trap 'rm -rf "$WORK"' EXIT
fi
WORK=$(cd "$WORK" && pwd)
rm -f "$WORK/history.sqlite"*
cat >"$WORK/tiny.toml" <<'EOF'
name = "tiny"
engines = ["embree", "grid", "bvh4"]
scenes = ["tetra"]
sf = [1]
repeats = 3
paired = 2
size = 24
gate = ["counters", "time_ratio", "instructions"]
commit_url = "https://git.example.org/rtbench/commit/{commit}"
[instructions]
engines = ["grid", "bvh4"]
scenes = ["tetra"]
sf = 1
size = 16
tolerance_pct = 0.01
EOF
night() { # [PLANT]
    local rc=0
    if [ $# -ge 1 ]; then
        RTBENCH_PLANT=$1 "$BIN" nightly --suite "$WORK/tiny.toml" --db "$WORK/history.sqlite" --out "$WORK/night" >/dev/null 2>&1 || rc=$?
    else
        env -u RTBENCH_PLANT "$BIN" nightly --suite "$WORK/tiny.toml" --db "$WORK/history.sqlite" --out "$WORK/night" >/dev/null 2>&1 || rc=$?
    fi
    echo "dashboard_screenshots.sh: night (plant: ${1:-none}): exit $rc" >&2
    [ "$rc" -le 1 ] || exit "$rc"
}
for _ in 1 2 3 4 5; do night; done
for _ in 6 7; do night "work:grid:tetra:0.5;counter:bvh4:tetra"; done
PAGE="$WORK/night/dashboard/index.html"
shot() { # NAME HEIGHT QUERY
    chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --no-first-run \
        --user-data-dir="$WORK/profile" --window-size="1400,$2" \
        --screenshot="docs/images/dashboard-$1.png" "file://$PAGE$3" >/dev/null 2>&1
    echo "dashboard_screenshots.sh: docs/images/dashboard-$1.png" >&2
}
mkdir -p docs/images
# The whole top of the page: gates, findings, the first plots.
shot overview 1500 ""
# The plots with a finding, night 6 held (as a hover holds it): values, interval, commit link, the finding.
shot findings 1700 "?flagged=1&night=6"
# The filter: bvh4's counters.
shot filter 1500 "?q=bvh4&kind=counter&night=7"
