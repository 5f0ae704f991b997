#!/usr/bin/env bash
# Submit an rtbench plan to Slurm as a job array plus a dependent merge job.
#
#   bash scripts/slurm/submit.sh run     SHARED [--shards N] -- --engines … --scenes … [run arguments]
#   bash scripts/slurm/submit.sh sweep   SHARED [--shards N] -- --engines … --scenes … --max-seconds S
#   bash scripts/slurm/submit.sh nightly SHARED [--shards N] --db HISTORY -- --suite FILE [nightly arguments]
#   bash scripts/slurm/submit.sh render  SHARED  --shards N  -- --scene STORE --engine breadth-first [--size …]
#
# SHARED is a directory every node sees (shard-K/ and merged/ are written there). The array has one
# task per shard: N defaults to the plan's groups (`rtbench plan --json`: a scene and its Embree run
# per group), and is capped there (more shards would be empty). Extra sbatch options go in
# $SBATCH_ARGS (e.g. "--partition=cpu --time=02:00:00"). Prints the two job ids.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
die() { echo "submit.sh: error: $*" >&2; exit 2; }
KIND="${1:-}"; SHARED="${2:-}"
[ -n "$KIND" ] && [ -n "$SHARED" ] || die "usage: submit.sh run|sweep|nightly|render SHARED [--shards N] [--db F] -- ARGS"
shift 2
SHARDS=""; DB=""
while [ $# -gt 0 ] && [ "$1" != "--" ]; do
    case "$1" in
        --shards) SHARDS="$2"; shift 2 ;;
        --db) DB="$2"; shift 2 ;;
        *) die "unknown option '$1' (before --)" ;;
    esac
done
[ "${1:-}" = "--" ] && shift
# The binary: $RTBENCH, else ./rtbench of an unpacked package (scripts/package.sh), else the clone's build.
if [ -z "${RTBENCH:-}" ]; then
    RTBENCH="$ROOT/target/release/rtbench"
    [ -x "$ROOT/rtbench" ] && RTBENCH="$ROOT/rtbench"
fi
[ -x "$RTBENCH" ] || die "$RTBENCH: not built (cargo build --release -p rtbench, or export RTBENCH)"
command -v sbatch >/dev/null || die "sbatch not found: install Slurm's client and set SLURM_CONF to your cluster's slurm.conf (or start a one-node cluster here: bash scripts/slurm/local-cluster.sh start)"
# A cluster must answer before anything is submitted (sbatch's own error would be a raw resolver
# or socket message and exit 1).
if ! scontrol ping 2>/dev/null | grep -q "is UP"; then
    die "no Slurm controller answers (${SLURM_CONF:-SLURM_CONF unset, the default slurm.conf}): set SLURM_CONF to your cluster's slurm.conf, or start a one-node cluster here: bash scripts/slurm/local-cluster.sh start"
fi
mkdir -p "$SHARED"
SHARED="$(cd "$SHARED" && pwd)"
[ -z "$(ls -A "$SHARED")" ] || die "$SHARED: not empty (each submission gets a directory of its own)"
case "$KIND" in
    run|sweep|nightly)
        plan_args=("$@")
        [ "$KIND" = "nightly" ] || plan_args+=(--out "$SHARED/plan-unused")
        groups="$("$RTBENCH" plan --json "$KIND" "${plan_args[@]}" | python3 -c 'import json,sys; print(json.load(sys.stdin)["groups"])')"
        N="${SHARDS:-$groups}"
        [ "$N" -le "$groups" ] || N="$groups"
        ;;
    render)
        [ -n "$SHARDS" ] || die "render: give --shards N (tiles)"
        N="$SHARDS"
        ;;
    *) die "unknown kind '$KIND' (run, sweep, nightly, render)" ;;
esac
[ "$KIND" != "nightly" ] || [ -n "$DB" ] || die "nightly: give --db HISTORY (the merge job records the night there)"
export RTBENCH
# shellcheck disable=SC2086
array=$(sbatch --parsable --export=ALL,RTBENCH="$RTBENCH" --array="1-$N" \
    --output="$SHARED/slurm-%A_%a.out" ${SBATCH_ARGS:-} \
    "$ROOT/scripts/slurm/shard.sbatch" "$KIND" "$SHARED" "$N" -- "$@")
array="${array%%;*}"
merge_args=()
if [ "$KIND" = "nightly" ]; then
    # The suite file is among the arguments; the merge job needs it and the history.
    suite=""; prev=""
    for a in "$@"; do [ "$prev" = "--suite" ] && suite="$a"; prev="$a"; done
    merge_args=(-- --suite "$suite" --db "$DB")
fi
# shellcheck disable=SC2086
merge=$(sbatch --parsable --export=ALL,RTBENCH="$RTBENCH" --dependency="afterany:$array" \
    --output="$SHARED/slurm-merge-%j.out" ${SBATCH_ARGS:-} \
    "$ROOT/scripts/slurm/merge.sbatch" "$KIND" "$SHARED" "$N" "${merge_args[@]}")
merge="${merge%%;*}"
echo "submit.sh: $KIND in $N shards: array job $array, merge job $merge; results in $SHARED/merged"
echo "$array $merge"
