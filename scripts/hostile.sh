#!/usr/bin/env bash
# The hostile suite, re-runnable: the reproducers of each round (views, limits, meshes, stores,
# plugins, history, merge and compare, suites), absurd settings, stdout to
# /dev/full and to a closed pipe for every command, mutated NFF files through several engines,
# and random bit flips in a scene store (scripts/store_bitflips.sh). Every invocation runs under
# a time limit and an address-space limit. It counts invocations, refusals (exit 2), panics
# (exit 101), aborts (killed by a signal other than SIGPIPE on a closed pipe), hangs (time limit)
# and silent wrong results (exit 0 where a refusal was due, or a store flip that rendered).
# Usage: bash scripts/hostile.sh [MUTATIONS=300] [FLIPS=200] [RTBENCH=target/release/rtbench]
# Exits 1 when any panic, abort, hang or silent wrong result was seen.
set -uo pipefail
MUTATIONS=${1:-300}
FLIPS=${2:-200}
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
B=${3:-$ROOT/target/release/rtbench}
[ -x "$B" ] || { echo "hostile.sh: $B not built (cargo build --release -p rtbench)" >&2; exit 2; }
WORK=$(mktemp -d -t rtbench-hostile.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
LIMIT_S=10
MEM_KB=$((4 * 1024 * 1024))

invocations=0 refused=0 ok=0 panics=0 aborts=0 hangs=0 wrong=0 other=0

# run EXPECT CMD...: EXPECT is 2 (a refusal is due), 0 (valid input), or any (either).
run() {
    local expect=$1
    shift
    invocations=$((invocations + 1))
    (ulimit -v $MEM_KB; timeout -s KILL $LIMIT_S "$B" "$@" >"$WORK/out" 2>"$WORK/err")
    tally $? "$expect" "$*"
}

tally() { # status expect label
    local rc=$1 expect=$2 label=$3
    case $rc in
        0) ok=$((ok + 1))
           if [ "$expect" = 2 ]; then wrong=$((wrong + 1)); echo "WRONG (exit 0, refusal due): $label" >&2; fi ;;
        2) refused=$((refused + 1))
           if [ "$expect" = 0 ]; then other=$((other + 1)); echo "refused valid input: $label: $(head -c 200 "$WORK/err")" >&2; fi
           if [ "$(wc -l <"$WORK/err")" -gt 1 ]; then other=$((other + 1)); echo "more than one line: $label" >&2; fi ;;
        101) panics=$((panics + 1)); echo "PANIC: $label: $(grep -m1 panicked "$WORK/err")" >&2 ;;
        137) hangs=$((hangs + 1)); echo "HANG (${LIMIT_S} s): $label" >&2 ;;
        1) other=$((other + 1)); echo "exit 1: $label: $(head -c 200 "$WORK/err")" >&2 ;;
        *) if [ "$rc" -gt 128 ]; then aborts=$((aborts + 1)); echo "SIGNAL $((rc - 128)): $label" >&2
           else other=$((other + 1)); echo "exit $rc: $label" >&2; fi ;;
    esac
}

nff() { # name view spheres → path
    printf 'v\nfrom 0 0 -5\nat 0 0 0\n%b\nhither 1\nresolution 8 8\n%b' "$2" "$3" >"$WORK/$1.nff"
    echo "$WORK/$1.nff"
}
GOOD="up 0 1 0\nangle 45"
ENGINES="reference embree grid bvh2 bvh4 bvh8 obvhs breadth-first object-space"

echo "hostile: reproducers" >&2
for view in "up 0 0 0\nangle 45" "up 0 0 1\nangle 45" "up 0 1 0\nangle 0" "up 0 1 0\nangle 180" \
            "up 0 1 0\nangle 360" "up 0 1 0\nangle -45"; do
    f=$(nff view "$view" "s 0 0 0 1\ns 2 0 0 1\n")
    for e in $ENGINES; do run 2 render --scene "$f" --engine "$e" --size 1; done
done
for s in "s 0 0 1e30 1" "s 1e300 0 0 1" "s 2 0 0 0" "s 0 0 0 -1" "c 0 0 0 0\n0 1 0 0" "s 0 nan 0 1"; do
    f=$(nff range "$GOOD" "s 0 0 0 1\n$s\n")
    for e in $ENGINES; do run 2 render --scene "$f" --engine "$e" --size 4; done
done
f=$(nff ok "$GOOD" "s 0 0 0 1\ns 2 0 0 1\n")
for e in $ENGINES; do run 0 render --scene "$f" --engine "$e" --size 8; done
for set in memory=18446744073709551615B buffer=18446744073709551615B memory=0 buffer=1 \
           memory=99999999999999999999999B registration=fixed:0 registration=fixed:4294967296; do
    run 2 render --scene "$f" --engine breadth-first --size 4 --set "$set"
done
for size in 0 16384 100000 -1; do run 2 render --scene "$f" --engine bvh2 --size $size; done
for t in 0 100000 -1; do run 2 render --scene "$f" --engine bvh2 --size 4 --threads $t; done
run 2 render --scene tree --sf 40 --engine bvh2 --size 4
run 2 render --scene tree --sf 0 --engine bvh2 --size 4
run 2 render --scene balls --sf 4294967296 --engine bvh2
run 2 tree-stats --scene tetra --sf 1 --width 1000000
run 2 render --scene "$WORK" --engine bvh2
run 2 render --scene /dev/null --engine bvh2
mkfifo "$WORK/fifo"; run 2 scene stats "$WORK/fifo"
printf '# empty\n' >"$WORK/empty.nff"; run 2 scene stats "$WORK/empty.nff"
awk 'BEGIN { printf "s 0 0 "; for (i = 0; i < 1048576; i++) printf "x"; printf "\033[31m 1\n" }' >"$WORK/long.nff"
run 2 scene stats "$WORK/long.nff"
awk 'BEGIN { n = 100000; print "p " n; for (i = 0; i < n; i++) print cos(6.2831853 * i / n), sin(6.2831853 * i / n), 0 }' >"$WORK/poly.nff"
run 2 scene stats "$WORK/poly.nff"
awk 'BEGIN { n = 16384; print "v\nfrom 0 0 -5\nat 0 0 0\nup 0 1 0\nangle 45\nhither 1\nresolution 8 8\np " n;
             for (i = 0; i < n; i++) print cos(6.2831853 * i / n), sin(6.2831853 * i / n), 0 }' >"$WORK/convex.nff"
run 0 render --scene "$WORK/convex.nff" --engine bvh2 --size 8
# compare: nothing matched, and B lacking A's runs (exit 1 is the due answer for the second).
run 0 run --engines bvh2 --scenes tetra --sf 1 --repeat 1 --size 8 --no-check --out "$WORK/ra"
run 0 run --engines bvh2 --scenes gears --sf 1 --repeat 1 --size 8 --no-check --out "$WORK/rb"
run 2 compare "$WORK/ra" "$WORK/rb"
run 0 run --engines bvh2 --scenes gears --sf 1 --repeat 1 --size 8 --no-check --resume --out "$WORK/ra"
invocations=$((invocations + 1))
(timeout -s KILL $LIMIT_S "$B" compare "$WORK/ra" "$WORK/rb" >"$WORK/out" 2>"$WORK/err")
rc=$?
if [ $rc = 1 ]; then ok=$((ok + 1)); else tally $rc 2 "compare with runs lost"; fi
# report with a figure of 1e308.
cp -r "$WORK/ra" "$WORK/r308"
sed -e 's/"mrays_per_s":[0-9.e+-]*/"mrays_per_s":1e308/' -e 's/"median":[0-9.e+-]*/"median":1e308/g' \
    "$WORK/ra/results.jsonl" >"$WORK/r308/results.jsonl"
for fmt in md csv json svg png html; do run any report "$WORK/r308" --format $fmt; done
# Scene stores: no materials, a 4 GB record length, a wrong object count are in the bit flips'
# reach and in harness/tests/hostile_cli.rs; here, a truncated geometry file and a missing one.
run 0 scene store tetra --sf 1 -o "$WORK/st"
cp -r "$WORK/st" "$WORK/st-trunc"; truncate -s -7 "$WORK/st-trunc/geometry.bin"
run 2 render --scene "$WORK/st-trunc" --engine breadth-first --size 8
cp -r "$WORK/st" "$WORK/st-miss"; rm "$WORK/st-miss/bbox.bin"
run 2 render --scene "$WORK/st-miss" --engine breadth-first --size 8

echo "hostile: stdout to /dev/full and to a closed pipe" >&2
COMMANDS=(
    "engines" "engines --json" "scene list" "scene list --json" "scene stats tetra" "scene stats tetra --json"
    "scene gen tetra --sf 1" "render --scene tetra --sf 1 --engine bvh2 --size 8"
    "render --scene tetra --sf 1 --engine bvh2 --size 8 --json" "check --scene tetra --sf 1 --engine bvh2 --size 8"
    "tree-stats --scene tetra --sf 1" "reproduce list" "compare $WORK/ra $WORK/ra"
    "render --scene $WORK/st --engine breadth-first --size 8"
)
for c in "${COMMANDS[@]}"; do
    if [ -w /dev/full ]; then
        invocations=$((invocations + 1))
        # shellcheck disable=SC2086
        (ulimit -v $MEM_KB; timeout -s KILL $LIMIT_S "$B" $c >/dev/full 2>"$WORK/err")
        tally $? 2 "$c > /dev/full"
    fi
    invocations=$((invocations + 1))
    # A closed pipe: the quiet end is SIGPIPE (141) or exit 0/2, never a panic.
    # shellcheck disable=SC2086
    (ulimit -v $MEM_KB; timeout -s KILL $LIMIT_S "$B" $c 2>"$WORK/err" | true)
    rc=${PIPESTATUS[0]}
    [ "$rc" = 141 ] && rc=0
    tally "$rc" any "$c | (closed)"
done

echo "hostile: meshes, limits, stores, plugins, history, merge and compare" >&2
M="$ROOT/tests/fuzz/corpus/mesh"
mkdir -p "$WORK/m/sub"
cp "$M"/* "$WORK/m/"
cp "$M/quad.bin" "$WORK/quad.bin"
gl() { # NAME SED-EXPRESSION [SEED]: a variant of a seed glTF (one-line JSON) → its path
    sed "$2" "${3:-$M/quad-data.gltf}" >"$WORK/m/$1.gltf"
    echo "$WORK/m/$1.gltf"
}
R="--engine bvh4 --size 8"
for f in quad-data.gltf quad.glb quad-file.gltf quad-le.ply quad-be.ply quad-ascii.ply quad.obj; do
    run 0 render --scene "$WORK/m/$f" $R
done
# glTF accessors against the spec: missing, wrong type or component, short stride, overruns.
run 2 render --scene "$(gl noacc 's/"accessors": \[.*\]}$/"accessors": []}/')" $R
run 2 render --scene "$(gl stride4 's/"byteStride": 12/"byteStride": 4/')" $R
run 2 render --scene "$(gl idxfloat 's/5123/5126/')" $R
for t in VEC2 VEC4 SCALAR MAT4; do
    run 2 render --scene "$(gl "pos$t" "s/\"VEC3\", \"min\"/\"$t\", \"min\"/")" $R
done
for c in 5121 5123; do
    run 2 render --scene "$(gl "posc$c" "s/\"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\", \"min\"/\"componentType\": $c, \"count\": 4, \"type\": \"VEC3\", \"min\"/")" $R
done
run 2 render --scene "$(gl idxover 's/"count": 6/"count": 9/')" $R
# Buffers only inside the mesh's folder: absolute, parent, device and scheme URIs refused.
for uri in /etc/passwd ../quad.bin /dev/zero file:///etc/passwd "$WORK/quad.bin"; do
    g=$(gl "uri$RANDOM" "s#\"uri\": \"quad.bin\"#\"uri\": \"$uri\"#" "$M/quad-file.gltf")
    run 2 render --scene "$g" $R
    if grep -q "root:" "$WORK/err"; then wrong=$((wrong + 1)); echo "WRONG (read outside the folder): $uri" >&2; fi
done
printf 'mtllib /dev/zero\nmtllib %s\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' "$WORK/m/quad.bin" >"$WORK/m/mtl.obj"
run 0 render --scene "$WORK/m/mtl.obj" $R
for n in 3 5; do
    sed "s/element vertex 4/element vertex $n/" "$M/quad-le.ply" >"$WORK/m/count$n.ply"
    run 2 render --scene "$WORK/m/count$n.ply" $R
done
# Limits: the memory estimate (tessellation, size factor, engine) against RAM and ulimit -v,
# the breadth-first budget, generation bounds, huge time budgets.
run 2 render --scene balls --sf 1 --engine bvh4 --tessellate 1000 --size 8
run 2 render --scene gears --sf 40 --engine bvh4 --size 8
run 2 render --scene balls --sf 1 --engine breadth-first --set memory=4294967295 --size 8
run 2 scene gen balls --sf 20
run 2 scene store mount --sf 20 -o "$WORK/big"
run 2 scene gen balls --sf 5 --max-bytes 100K
run 0 scene store tetra --sf 3 --segment 16 --max-seconds 1e308 -o "$WORK/st3"
run 2 render --scene tetra --sf 1 $R --threads 1000000
# A compressed basic store's header.json is vouched for; a store directory without it is named.
for c in gzip:1 zstd; do
    rm -rf "$WORK/cs"
    run 0 scene store balls --sf 1 --layout basic --compress $c -o "$WORK/cs"
    printf ' ' >>"$WORK/cs/header.json"
    run 2 render --scene "$WORK/cs" --engine breadth-first --set layout=basic --size 8
done
mkdir -p "$WORK/nohdr" && : >"$WORK/nohdr/bbox.bin"
run 2 render --scene "$WORK/nohdr" --engine breadth-first --size 8
# Plugins: answers held to the ABI, output kept off stdout, messages escaped.
if command -v cc >/dev/null; then
    for f in OK BARY PRIM0 STDOUT ESC; do
        d=""; [ $f = OK ] || d="-DRTB_FAULT_$f"
        cc -O2 -shared -fPIC -std=c99 -I"$ROOT/include" $d "$ROOT/examples/c-bvh/bvh.c" -o "$WORK/p$f.so" -lm
    done
    P="render --scene balls --sf 1 --size 16 --json --engine plugin:$WORK/p"
    run 2 $P"BARY.so"
    run 0 $P"STDOUT.so"
    if grep -q "c-bvh" "$WORK/out" || [ "$(head -c 1 "$WORK/out")" != "{" ]; then wrong=$((wrong + 1)); echo "WRONG (plugin output in the JSON)" >&2; fi
    run 2 $P"ESC.so"
    if grep -q $'\x1b' "$WORK/err"; then wrong=$((wrong + 1)); echo "WRONG (raw escape from a plugin)" >&2; fi
    run 2 $P"OK.so:abi_timing=bogus"
    invocations=$((invocations + 1))
    (ulimit -v $MEM_KB; timeout -s KILL $LIMIT_S "$B" check --scene balls --sf 1 --size 16 --engine "plugin:$WORK/pPRIM0.so" >"$WORK/out" 2>"$WORK/err")
    rc=$?
    if [ $rc = 1 ]; then refused=$((refused + 1)); else tally $rc 2 "check with a plugin naming primitive 0"; fi
fi
# Results: duplicates, an empty file, impossible times; merge of a shard holding a run twice.
S="$ROOT/tests/fuzz/corpus/shard"
mkdir -p "$WORK/sh" "$WORK/dup" "$WORK/empty" "$WORK/neg"
cp "$S"/* "$WORK/sh/"
run 0 merge "$WORK/sh" --out "$WORK/merged"
head -1 "$S/results.jsonl" >>"$WORK/sh/results.jsonl"
run 2 merge "$WORK/sh" --out "$WORK/merged2"
cp "$WORK/sh/results.jsonl" "$WORK/dup/results.jsonl"
run 2 compare "$WORK/merged" "$WORK/dup"
: >"$WORK/empty/results.jsonl"
run 2 compare "$WORK/merged" "$WORK/empty"
run 2 report "$WORK/empty"
sed 's/"median":\([0-9]\)/"median":-\1/' "$S/results.jsonl" >"$WORK/neg/results.jsonl"
run 2 compare "$WORK/merged" "$WORK/neg"
# Suites are checked whole before a night measures anything.
for bad in 'engines = ["embree", "grid:simd=off"]' 'threads = [1000000]' 'sf = [40]'; do
    { echo 'engines = ["embree", "grid"]'; echo 'scenes = ["gears"]'; echo 'sf = [1]'; echo 'repeats = 2'; echo 'size = 8'; echo 'gate = ["counters"]'; } >"$WORK/suite.toml"
    key=${bad%% =*}
    sed -i "/^$key =/d" "$WORK/suite.toml"
    echo "$bad" >>"$WORK/suite.toml"
    run 2 nightly --suite "$WORK/suite.toml" --db "$WORK/suite.sqlite"
    run 2 plan nightly --suite "$WORK/suite.toml"
done
# History: read commands never write, text is cut at characters, check sees what is missing.
{ echo 'engines = ["embree", "grid"]'; echo 'scenes = ["tetra"]'; echo 'sf = [1]'; echo 'repeats = 2'; echo 'size = 8'; echo 'gate = ["counters"]'; } >"$WORK/night.toml"
H="$WORK/hist/h.sqlite"
mkdir -p "$WORK/hist"
if timeout 300 "$B" nightly --suite "$WORK/night.toml" --db "$H" >/dev/null 2>&1 && command -v sqlite3 >/dev/null; then
    sqlite3 "$H" "UPDATE runs SET git_commit='日日日日日', fingerprint='日日日日日日日日日日日日日';"
    for c in list show "export --format csv" "export --format bmf" check; do run 0 history $c --db "$H"; done
    run 2 history export --format bmf --run 99 --db "$H"
    run 2 history dashboard --db "$H" --out /proc/none
    chmod 555 "$WORK/hist"
    for c in list show "export --format csv" check; do run 0 history $c --db "$H"; done
    chmod 755 "$WORK/hist"
    : >"$WORK/zero.sqlite"
    run 2 history list --db "$WORK/zero.sqlite"
    [ -s "$WORK/zero.sqlite" ] && { wrong=$((wrong + 1)); echo "WRONG (a read command wrote a schema)" >&2; }
    for damage in "DROP TABLE samples" "ALTER TABLE findings RENAME COLUMN message TO msg" \
                  "UPDATE metrics SET value = 'fast'" "DELETE FROM metrics WHERE run_id = 2 AND rowid % 2 = 0"; do
        cp "$H" "$WORK/d.sqlite"
        sqlite3 "$WORK/d.sqlite" "INSERT INTO runs SELECT id + 1, suite, suite_sha256, started_at, finished_at, git_commit, git_dirty, fingerprint, env_json, wall_s, regressions, note FROM runs WHERE id = 1; INSERT INTO metrics SELECT run_id + 1, name, kind, unit, value, gated FROM metrics WHERE run_id = 1; $damage;" 2>/dev/null
        invocations=$((invocations + 1))
        (timeout -s KILL $LIMIT_S "$B" history check --db "$WORK/d.sqlite" >"$WORK/out" 2>"$WORK/err")
        rc=$?
        if [ $rc = 1 ]; then refused=$((refused + 1)); else tally $rc 2 "history check after: $damage"; fi
    done
fi

echo "hostile: $MUTATIONS mutated NFF files" >&2
SEEDS=("$ROOT"/tests/fuzz/corpus/nff/*.nff)
TOKENS="nan inf -inf 1e308 -1e308 1e30 0 -1 -0 4294967296 99999999999999999999 x p pp s c v f l b # 16384 1e-320"
for ((i = 0; i < MUTATIONS; i++)); do
    seed=${SEEDS[$((i % ${#SEEDS[@]}))]}
    awk -v seed="$i" -v tokens="$TOKENS" 'BEGIN { srand(seed); n = split(tokens, t, " ") }
        { lines[NR] = $0 }
        END {
            m = 1 + int(rand() * 4)
            for (k = 0; k < m; k++) {
                r = 1 + int(rand() * NR); c = split(lines[r], f, " ")
                op = int(rand() * 3)
                if (op == 0 && c > 0) { f[1 + int(rand() * c)] = t[1 + int(rand() * n)] }
                else if (op == 1) { f[c + 1] = t[1 + int(rand() * n)]; c++ }
                else { lines[r] = ""; c = 0 }
                s = ""; for (j = 1; j <= c; j++) s = s (j > 1 ? " " : "") f[j]; if (c > 0) lines[r] = s
            }
            for (r = 1; r <= NR; r++) print lines[r]
        }' "$seed" >"$WORK/m.nff"
    for e in bvh4 obvhs grid breadth-first; do run any render --scene "$WORK/m.nff" --engine $e --size 8; done
done

echo "hostile: $FLIPS store bit flips" >&2
line=$(bash "$ROOT/scripts/store_bitflips.sh" "$FLIPS" 14 "$B" 2>"$WORK/flips.err" | tail -1)
read -r _ n _ r _ same _ diff _ p _ s _ h _ o <<<"$line"
invocations=$((invocations + n + 1))
refused=$((refused + r)); panics=$((panics + p)); aborts=$((aborts + s)); hangs=$((hangs + h))
wrong=$((wrong + same + diff)); other=$((other + o))
[ -s "$WORK/flips.err" ] && head -5 "$WORK/flips.err" >&2

echo "invocations $invocations refused $refused ok $ok panics $panics aborts $aborts hangs $hangs silent_wrong $wrong other $other"
[ $((panics + aborts + hangs + wrong)) -eq 0 ]
