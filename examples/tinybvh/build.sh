#!/usr/bin/env bash
# Builds the tinybvh plugin: plugin.cpp against the tinybvh header that the tinybvh-rs crate ships,
# with AVX2 and FMA enabled for this library only (tinybvh's BVH8_CPU traversal needs them at
# compile time; the rest of rtbench keeps its own code generation).
# Output: target/tinybvh/librtbench_tinybvh.so at the workspace root, where the `tinybvh` engine
# looks (or OUT, the first argument). Needs a C++17 compiler (CXX, default c++) and cargo.
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
OUT="${1:-$ROOT/target/tinybvh/librtbench_tinybvh.so}"
[ -x "$HOME/.cargo/bin/cargo" ] && export PATH="$HOME/.cargo/bin:$PATH"
MANIFEST="$(cargo metadata --format-version 1 --manifest-path "$HERE/Cargo.toml" \
  | python3 -c 'import json,sys; m=json.load(sys.stdin); print(next(p["manifest_path"] for p in m["packages"] if p["name"]=="tinybvh-rs"))')"
HEADER_DIR="$(dirname "$MANIFEST")/ffi/tinybvh"
[ -f "$HEADER_DIR/tiny_bvh.h" ] || { echo "tinybvh/build.sh: error: no tiny_bvh.h in $HEADER_DIR" >&2; exit 1; }
mkdir -p "$(dirname "$OUT")"
# Only rebuild when the source, the header or this script is newer than the library.
if [ -f "$OUT" ] && [ "$OUT" -nt "$HERE/plugin.cpp" ] && [ "$OUT" -nt "$HEADER_DIR/tiny_bvh.h" ] \
  && [ "$OUT" -nt "$HERE/build.sh" ] && [ "$OUT" -nt "$ROOT/include/rtbench_engine.h" ]; then
  exit 0
fi
"${CXX:-c++}" -std=c++17 -O3 -mavx2 -mfma -fPIC -shared -fvisibility=hidden -pthread \
  -I"$ROOT/include" -I"$HEADER_DIR" "$HERE/plugin.cpp" -o "$OUT.tmp"
mv "$OUT.tmp" "$OUT"
