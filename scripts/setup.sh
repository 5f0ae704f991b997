#!/usr/bin/env bash
# Set up what rtbench needs beyond Cargo: libclang (for embree4-sys's bindgen) and Embree 4 itself.
#
# Embree comes from the `embreex` wheel on PyPI (manylinux x86_64): its `embreex.libs/` folder holds
# `libembree4-<hash>.so.4` and `libtbb-<hash>.so.12` (rpath `$ORIGIN`). Only those two files are unpacked, into
# `.embree/lib/` at the repository root (git-ignored), with the links the linker and the loader need:
#   libembree4.so   -> libembree4-<hash>.so.4   (the name `-lembree4` looks for at link time)
#   <SONAME>        -> libembree4-<hash>.so.4   (the name recorded in binaries, found at run time via rpath)
# The build finds the folder through .cargo/config.toml and engines/build.rs; nothing else is installed.
#
# Idempotent and quiet when everything is already in place. Usage: bash scripts/setup.sh
set -euo pipefail

EMBREEX_VERSION="4.4.0.post1"
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
LIB_DIR="$ROOT/.embree/lib"

die() { echo "setup.sh: error: $*" >&2; exit 1; }
say() { echo "setup.sh: $*"; }

[ "$(uname -s)-$(uname -m)" = "Linux-x86_64" ] || die "only Linux x86_64 is supported (Embree comes from a manylinux x86_64 wheel)"

# --- libclang (bindgen in embree4-sys) -------------------------------------------------------------------------
if ! dpkg-query -W -f='${Status}' libclang-dev 2>/dev/null | grep -q "install ok installed"; then
    command -v apt-get >/dev/null || die "libclang-dev is missing and apt-get is not available; install libclang by hand"
    SUDO=""
    if [ "$(id -u)" -ne 0 ]; then
        command -v sudo >/dev/null || die "libclang-dev is missing; run as root or install sudo"
        SUDO="sudo"
    fi
    say "installing libclang-dev with apt-get"
    log="$(mktemp)"
    if ! { $SUDO env DEBIAN_FRONTEND=noninteractive apt-get update -qq \
        && $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends libclang-dev; } \
        >"$log" 2>&1; then
        tail -n 20 "$log" >&2
        rm -f "$log"
        die "apt-get install libclang-dev failed (output above)"
    fi
    rm -f "$log"
fi

# --- Embree 4 ----------------------------------------------------------------------------------------------------
embree_ok() {
    [ -e "$LIB_DIR/libembree4.so" ] || return 1
    local real soname
    real="$(readlink -f "$LIB_DIR/libembree4.so")" || return 1
    [ -f "$real" ] || return 1
    compgen -G "$LIB_DIR/libtbb-*.so.12" >/dev/null || return 1
    soname="$(soname_of "$real")" || return 1
    [ -e "$LIB_DIR/$soname" ]
}

# SONAME of a shared library, read with readelf if present, else with a few lines of Python (always there: pip
# is needed anyway).
soname_of() {
    if command -v readelf >/dev/null; then
        readelf -d "$1" | sed -n 's/.*(SONAME).*\[\(.*\)\].*/\1/p'
    else
        python3 - "$1" <<'EOF'
import struct, sys
d = open(sys.argv[1], "rb").read()
assert d[:4] == b"\x7fELF" and d[4] == 2 and d[5] == 1, "not a 64-bit little-endian ELF"
shoff, = struct.unpack_from("<Q", d, 0x28)
shentsize, shnum = struct.unpack_from("<HH", d, 0x3A)
secs = [struct.unpack_from("<IIQQQQIIQQ", d, shoff + i * shentsize) for i in range(shnum)]
for s in secs:
    if s[1] == 6:  # SHT_DYNAMIC; sh_link is its string table
        strtab = secs[s[6]]
        for off in range(s[4], s[4] + s[5], 16):
            tag, val = struct.unpack_from("<qQ", d, off)
            if tag == 14:  # DT_SONAME
                start = strtab[4] + val
                print(d[start:d.index(b"\0", start)].decode())
                sys.exit(0)
sys.exit(1)
EOF
    fi
}

if ! embree_ok; then
    command -v python3 >/dev/null || die "python3 is needed to download Embree (the embreex wheel from PyPI)"
    python3 -m pip --version >/dev/null 2>&1 || die "python3 has no pip; install python3-pip"
    tmp="$(mktemp -d)"
    trap 'rm -rf "$tmp"' EXIT
    say "downloading Embree 4 (embreex==$EMBREEX_VERSION wheel from PyPI)"
    if ! python3 -m pip download --quiet --no-deps --only-binary=:all: \
        --platform manylinux_2_28_x86_64 --platform manylinux2014_x86_64 --platform manylinux_2_17_x86_64 \
        --python-version 3.11 --implementation cp \
        --dest "$tmp" "embreex==$EMBREEX_VERSION" >"$tmp/pip.log" 2>&1; then
        tail -n 20 "$tmp/pip.log" >&2
        die "pip download embreex==$EMBREEX_VERSION failed (output above)"
    fi
    wheel="$(compgen -G "$tmp/embreex-*.whl" | head -n 1)" || true
    [ -n "$wheel" ] || die "pip did not produce an embreex wheel"
    mkdir -p "$tmp/x"
    python3 - "$wheel" "$tmp/x" <<'EOF' || die "could not unpack Embree from the wheel"
import fnmatch, os, sys, zipfile
wheel, dest = sys.argv[1], sys.argv[2]
want = ("embreex.libs/libembree4-*.so.4", "embreex.libs/libtbb-*.so.12")
got = []
with zipfile.ZipFile(wheel) as z:
    for name in z.namelist():
        if any(fnmatch.fnmatch(name, p) for p in want):
            out = os.path.join(dest, os.path.basename(name))
            with z.open(name) as src, open(out, "wb") as dst:
                dst.write(src.read())
            got.append(os.path.basename(name))
missing = [p for p in want if not any(fnmatch.fnmatch("embreex.libs/" + g, p) for g in got)]
if missing:
    sys.exit("missing in wheel: " + ", ".join(missing))
EOF
    embree="$(compgen -G "$tmp/x/libembree4-*.so.4" | head -n 1)"
    soname="$(soname_of "$embree")" || true
    [ -n "$soname" ] || die "could not read the SONAME of $(basename "$embree")"
    mkdir -p "$LIB_DIR"
    rm -f "$LIB_DIR"/libembree4* "$LIB_DIR"/libtbb*
    cp "$tmp/x/"*.so.* "$LIB_DIR/"
    chmod 755 "$LIB_DIR"/*.so.*
    ln -sf "$(basename "$embree")" "$LIB_DIR/libembree4.so"
    [ "$soname" = "$(basename "$embree")" ] || ln -sf "$(basename "$embree")" "$LIB_DIR/$soname"
    embree_ok || die "Embree was unpacked into $LIB_DIR but is incomplete"
    say "Embree 4 ready in .embree/lib ($(basename "$embree"))"
fi

# --- Meshes for the examples and docs -----------------------------------------------------------------
# Real meshes from Debian packages, into .meshes/ (git-ignored, never committed):
#   bunny.ply            the Stanford bunny (75,408 triangles, a range scan), from libcgal-demo's
#                        data/meshes/bunny00.off, converted to ASCII PLY here
#   wuson.obj            assimp-testmodels' models/OBJ/WusonOBJ.obj
#   2CylinderEngine.glb  assimp-testmodels' models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb
# A failure here is a warning: rtbench builds and tests without them.
MESH_DIR="$ROOT/.meshes"
SUDO="${SUDO:-}"
meshes_ok() { [ -s "$MESH_DIR/bunny.ply" ] && [ -s "$MESH_DIR/wuson.obj" ] && [ -s "$MESH_DIR/2CylinderEngine.glb" ]; }
fetch_meshes() {
    command -v apt-get >/dev/null && command -v dpkg-deb >/dev/null || { echo "apt-get/dpkg-deb not available"; return 1; }
    local t
    t="$(mktemp -d)"
    # apt-get download runs as the _apt user when it can: give it a folder it may write.
    chmod 777 "$t"
    ( cd "$t" && { apt-get download -qq libcgal-demo assimp-testmodels 2>/dev/null \
        || { $SUDO apt-get update -qq && apt-get download -qq libcgal-demo assimp-testmodels; }; } ) || return 1
    dpkg-deb -x "$t"/libcgal-demo_*.deb "$t/cgal" && dpkg-deb -x "$t"/assimp-testmodels_*.deb "$t/assimp" || return 1
    tar -xzf "$t/cgal/usr/share/doc/libcgal-dev/data.tar.gz" -C "$t" data/meshes/bunny00.off || return 1
    mkdir -p "$MESH_DIR"
    python3 - "$t/data/meshes/bunny00.off" "$MESH_DIR/bunny.ply" <<'PY' || return 1
import sys
words = open(sys.argv[1]).read().split()
assert words[0] == "OFF", "not an OFF file"
nv, nf = int(words[1]), int(words[2])
v = words[4:4 + 3 * nv]
rest = words[4 + 3 * nv:]
faces, i = [], 0
for _ in range(nf):
    k = int(rest[i]); faces.append(rest[i + 1:i + 1 + k]); i += 1 + k
with open(sys.argv[2], "w") as out:
    out.write("ply\nformat ascii 1.0\ncomment Stanford bunny (bunny00.off of CGAL's data)\n")
    out.write(f"element vertex {nv}\nproperty float x\nproperty float y\nproperty float z\n")
    out.write(f"element face {nf}\nproperty list uchar int vertex_indices\nend_header\n")
    for j in range(nv):
        out.write(" ".join(v[3 * j:3 * j + 3]) + "\n")
    for f in faces:
        out.write(f"{len(f)} " + " ".join(f) + "\n")
PY
    cp "$t/assimp/usr/share/assimp/models/OBJ/WusonOBJ.obj" "$MESH_DIR/wuson.obj" || return 1
    cp "$t/assimp/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb" "$MESH_DIR/" || return 1
    rm -rf "$t"
}
if ! meshes_ok; then
    say "fetching example meshes into .meshes/ (Debian packages libcgal-demo, assimp-testmodels)"
    if fetch_meshes && meshes_ok; then
        say "meshes ready in .meshes/"
    else
        say "warning: could not fetch the example meshes; rtbench works without them"
    fi
fi
# The `tinybvh` engine's plugin: tinybvh's header (shipped by the tinybvh-rs crate) compiled with AVX2 for that
# library alone. Without a C++ compiler or AVX2 the engine is listed as unavailable and the rest works.
if grep -q avx2 /proc/cpuinfo 2>/dev/null && bash examples/tinybvh/build.sh; then
    :
else
    say "warning: the tinybvh plugin was not built; the tinybvh engine is unavailable"
fi
