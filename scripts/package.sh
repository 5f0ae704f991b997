#!/usr/bin/env bash
# A relocatable rtbench: the release binary with Embree (and its TBB) beside it, in one tarball that
# runs from any folder on any node of the same OS, without the clone.
#
#   bash scripts/package.sh [OUT_DIR]        builds (cargo build --release -p rtbench) unless $RTBENCH
#                                            names a built binary; writes OUT_DIR/rtbench-<commit>-<arch>.tar.gz
#                                            (default OUT_DIR: out/package) and prints its path
#
# The tarball holds rtbench-<commit>-<arch>/ with:
#   rtbench            the binary, its run path set to $ORIGIN/lib (debug info stripped, symbols kept:
#                      the nightly's instruction counts find their traced region by its symbol)
#   lib/               Embree 4 and TBB, as scripts/setup.sh installed them
#   scripts/slurm/     submit.sh, shard.sbatch, merge.sbatch, local-cluster.sh (submit.sh finds ./rtbench)
#   suites/            the suite files
#
# Where the binary finds Embree: the library it was built with if that path exists on the node (the
# clone's .embree/lib), else libembree4.so in lib/ beside itself (the $ORIGIN run path), else in the
# folders of LD_LIBRARY_PATH, then the system's. `rtbench engines` says whether Embree loaded.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
die() { echo "package.sh: error: $*" >&2; exit 2; }
OUT="${1:-$ROOT/out/package}"
cd "$ROOT"
EMBREE_LIB="$ROOT/.embree/lib"
[ -e "$EMBREE_LIB/libembree4.so" ] || die "$EMBREE_LIB/libembree4.so missing (bash scripts/setup.sh installs Embree)"
if [ -n "${RTBENCH:-}" ]; then
    [ -x "$RTBENCH" ] || die "RTBENCH=$RTBENCH: not an executable"
    BIN="$RTBENCH"
else
    cargo build --release -p rtbench >&2
    BIN="$ROOT/target/release/rtbench"
fi
if ! command -v patchelf >/dev/null; then
    command -v apt-get >/dev/null || die "patchelf is missing and apt-get is not available to install it"
    echo "package.sh: installing patchelf" >&2
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq patchelf >/dev/null 2>&1 \
        || { DEBIAN_FRONTEND=noninteractive apt-get update -qq >/dev/null 2>&1 \
             && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq patchelf >/dev/null 2>&1; } \
        || die "apt-get install patchelf failed"
fi
commit="$(git rev-parse --short=12 HEAD 2>/dev/null || echo unknown)"
name="rtbench-$commit-$(uname -m)"
stage="$(mktemp -d)"
trap 'rm -rf "$stage"' EXIT
pkg="$stage/$name"
mkdir -p "$pkg/lib" "$pkg/scripts/slurm" "$pkg/suites"
objcopy --strip-debug "$BIN" "$pkg/rtbench"
patchelf --set-rpath '$ORIGIN/lib' "$pkg/rtbench"
# The library files and their links (libembree4.so → the versioned file), as they are.
cp -P "$EMBREE_LIB"/* "$pkg/lib/"
cp scripts/slurm/submit.sh scripts/slurm/shard.sbatch scripts/slurm/merge.sbatch \
    scripts/slurm/local-cluster.sh "$pkg/scripts/slurm/"
cp suites/*.toml "$pkg/suites/"
# The packaged binary must start and find Embree beside itself before it is shipped.
"$pkg/rtbench" --version >/dev/null || die "the packaged binary does not start"
mkdir -p "$OUT"
OUT="$(cd "$OUT" && pwd)"
tar -C "$stage" -czf "$OUT/$name.tar.gz" "$name"
echo "$OUT/$name.tar.gz"
