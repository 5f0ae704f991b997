#!/usr/bin/env python3
"""The tables of docs/benchmarks.md from the runs of scripts/benchmarks.sh: python3 scripts/benchmarks.py OUT.

A ratio measured in pairs over rounds (`run --repeat 3 --paired 9`: three processes, each round's median of its
pairs) is shown with the 95 % interval `rtbench run` gives it, Student's t over the rounds. Other intervals are
distribution-free 95 % intervals of a median from the order statistics of its samples (the binomial ranks; with 7
samples, the smallest and largest: 98 % coverage; with 9, the 2nd and 8th: 96 %). Fewer than 6 samples give no
interval at 95 % and are shown as their range, marked "range"."""
import json
import math
import os
import sys

ORDER = ["balls4", "gears4", "mount6", "rings7", "teapot12", "tetra6", "tree11"]


def records(d):
    path = os.path.join(d, "results.jsonl")
    if not os.path.exists(path):
        return []
    return [json.loads(l) for l in open(path) if l.strip()]


def env_line(d):
    try:
        e = json.load(open(os.path.join(d, "env.json")))
    except OSError:
        return "environment not recorded"
    dirty = " (with uncommitted changes)" if e.get("git_dirty") else ""
    return (f"{e.get('started_at', '?')[:16].replace('T', ' ')} UTC, commit {e.get('git_commit', '?')[:10]}{dirty}, "
            f"{e.get('cpu_model', '?')}, {e.get('cores_logical', '?')} logical cores, "
            f"{e.get('memory_bytes', 0) / 2**30:.1f} GiB, {e.get('os', '?')}, Embree {e.get('embree_version', '?')}")


def median_ci(xs):
    """(median, lo, hi, exact) with a >= 95 % order-statistic interval when the sample allows one."""
    xs = sorted(xs)
    n = len(xs)
    if n == 0:
        return None
    med = xs[n // 2] if n % 2 else 0.5 * (xs[n // 2 - 1] + xs[n // 2])
    best = None
    for k in range(0, n // 2):
        # P(X_(k+1) <= median <= X_(n-k)) = 1 - 2 * P(Bin(n, 1/2) <= k)
        cover = 1 - 2 * sum(math.comb(n, i) for i in range(k + 1)) / 2 ** n
        if cover >= 0.95:
            best = (xs[k], xs[n - 1 - k])
    if best is None:
        return med, xs[0], xs[-1], False
    return med, best[0], best[1], True


def pairs_ci(r, spread):
    """A paired figure's (estimate, lo, hi, exact): over the run's rounds when it ran in two or more (the
    interval its record carries), else from the order statistics of its pairs."""
    i = spread.get("interval")
    if len((r or {}).get("rounds") or []) >= 2 and i:
        return i["estimate"], i["lo"], i["hi"], True
    return median_ci(spread["samples"])


def fmt_ci(c, digits=2):
    if c is None:
        return "–"
    med, lo, hi, exact = c
    tag = "" if exact else " range"
    return f"{med:.{digits}f} [{lo:.{digits}f}, {hi:.{digits}f}{tag}]"


def label(r):
    s = r.get("settings") or {}
    if not s:
        return r["engine"]
    return r["engine"] + "[" + ",".join(f"{k}={v}" for k, v in sorted(s.items())) + "]"


def by_scene(recs):
    out = {}
    for r in recs:
        if r.get("status") != "ok":
            continue
        out.setdefault(r["scene"]["name"], {})[label(r)] = r
    return out


def scenes_of(table):
    return [s for s in ORDER if s in table] + sorted(s for s in table if s not in ORDER)


# Columns in this order (Embree, the grid, the BVHs by width, the peers), whatever order the records are in: a run
# that gives some jobs further rounds writes their records last.
ENGINE_ORDER = ["embree", "grid", "bvh2", "bvh4", "bvh8", "obvhs", "tinybvh", "breadth-first", "object-space"]


def engines_of(recs):
    seen = []
    for r in recs:
        if label(r) not in seen:
            seen.append(label(r))
    rank = {e: i for i, e in enumerate(ENGINE_ORDER)}
    return sorted(seen, key=lambda e: (rank.get(e.split("[")[0], len(ENGINE_ORDER)), seen.index(e)))


def md(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(out)


def failures(recs):
    bad = [r for r in recs if r.get("status") != "ok"]
    return "".join(f"\nFailed: `{r['key']}`: {r.get('reason')}" for r in bad)


def speed(d):
    recs = records(d)
    t = by_scene(recs)
    engines = [e for e in engines_of(recs) if e != "embree"]
    rows, logs = [], {e: [] for e in engines}
    for s in scenes_of(t):
        row = [s, f"{t[s]['embree']['mrays_per_s']:.2f}" if "embree" in t[s] else "–"]
        for e in engines:
            r = t[s].get(e)
            p = (r or {}).get("paired_ratio")
            c = pairs_ci(r, p) if p else None
            if c:
                logs[e].append(math.log(c[0]))
            agree = (r or {}).get("check") or {}
            mark = "" if not agree or agree.get("hit_agreement", 0) >= 0.9999 else " ✗"
            row.append(fmt_ci(c) + mark)
        rows.append(row)
    rows.append(["geometric mean", ""] + [f"{math.exp(sum(v) / len(v)):.2f}" if v else "–" for e, v in logs.items()])
    return md(["scene", "embree Mrays/s"] + [f"{e} ÷ embree" for e in engines], rows) + failures(recs)


def memory(d):
    recs = records(d)
    t = by_scene(recs)
    engines = engines_of(recs)
    rows = []
    for s in scenes_of(t):
        prims = next(iter(t[s].values()))["scene"]["primitives"]
        row = [s, f"{prims:,}"]
        for e in engines:
            r = t[s].get(e)
            row.append(f"{r['structure_bytes'] / prims:.0f} / {r['peak_rss_bytes'] / 2**20:.0f}" if r else "–")
        rows.append(row)
    return md(["scene", "primitives"] + [f"{e} B/prim / peak MiB" for e in engines], rows)


def per_engine(d, cell):
    """A table of one row per scene and one column per engine, each cell `cell(record)` (– without a run)."""
    recs = records(d)
    t = by_scene(recs)
    engines = engines_of(recs)
    rows = [[s] + [cell(t[s][e]) if e in t[s] else "–" for e in engines] for s in scenes_of(t)]
    return recs, engines, rows


def build(d):
    _, engines, rows = per_engine(
        d, lambda r: fmt_ci(median_ci([x * 1e3 for x in r['time_s']['build']['samples']]), 1))
    return md(["scene"] + [f"{e} ms" for e in engines], rows)


def grid(d):
    recs = records(d)
    t = by_scene(recs)
    engines = engines_of(recs)
    rows = []
    for s in scenes_of(t):
        for e in engines:
            r = t[s].get(e)
            if not r:
                continue
            c, rays = r["counters"], max(r["counters"].get("rays", 0), 1)
            extra = c.get("extra", {}) if isinstance(c.get("extra"), dict) else {}
            rows.append([s, e, f"{c.get('primitive_tests', 0) / rays:.2f}", f"{c.get('cells_visited', 0) / rays:.2f}",
                         f"{c.get('empty_cells_visited', 0) / rays:.2f}", f"{c.get('mailbox_skips', 0) / rays:.2f}",
                         f"{c.get('shadow_cache_hits', 0):,}", f"{c.get('box_tests', 0) / rays:.2f}"])
    return md(["scene", "engine", "tests/ray", "cells/ray", "empty cells/ray", "mailbox skips/ray",
               "shadow-cache hits", "culling box tests/ray"], rows)


def ooc(d):
    rows = []
    for name, what in [("memory-grid.json", "grid, in memory"), ("memory-bf.json", "breadth-first, in memory"),
                       ("store-32MiB.json", "breadth-first, store, memory=32MiB"),
                       ("store-8MiB.json", "breadth-first, store, memory=8MiB")]:
        p = os.path.join(d, name)
        if not os.path.exists(p):
            continue
        j = json.load(open(p))
        ex = (j.get("counters") or {}).get("extra") or {}
        io = j.get("io") or {}
        read = ex.get("io_bytes_read", io.get("bytes_read", 0))
        rows.append([what, f"{j['time_s']['preprocess']:.2f}", f"{j['time_s']['trace']:.2f}",
                     f"{j['memory']['peak_rss_bytes'] / 2**20:.0f}", f"{read / 2**20:.0f}" if read else "–",
                     ex.get("bf_passes", "–"), (j.get("image") or {}).get("sha256", "")[:12]])
    return md(["mount8 (131,076 objects)", "preprocess s", "trace s", "peak RSS MiB", "MiB read", "passes",
               "image sha256"], rows)


def goals(j):
    """Our engines' goals (kimura-simd's tables beside 001's claim, not claims of 001): the goal rows, then what
    each factor of the SIMD traversal is worth on the same trees."""
    g = md(["scene", "ratio", "goal", "measured", "met"],
           [[r["scene"], r["ratio"], r["goal"], f"{r['measured']:.2f}", "yes" if r["met"] else "**no**"]
            for r in j["goals"]])
    f = md(["scene", "factor", "ratio", "numerator ÷ denominator"],
           [[r["scene"], r["factor"], f"{r['ratio']:.2f}", f"{r['over']} ÷ {r['under']}"] for r in j["factors"]])
    return f"{g}\n\n{f}"


# The performance targets: each table judges one target on the runs of its own command.


def paired(r):
    """A run's paired time ratio to Embree as (estimate, lo, hi, exact), or None."""
    p = (r or {}).get("paired_ratio")
    return pairs_ci(r, p) if p else None


def inverse(c):
    """Speed from a time ratio: (1/estimate, 1/hi, 1/lo)."""
    return None if c is None else (1 / c[0], 1 / c[2], 1 / c[1], c[3])


def quotient(a, b):
    """a ÷ b of two figures with intervals, the interval from their bounds (each side's 95 % interval at its
    worst: wider than the interval of the quotient itself)."""
    if a is None or b is None:
        return None
    return a[0] / b[0], a[1] / b[2], a[2] / b[1], a[3] and b[3]


T95 = {1: 12.706, 2: 4.303, 3: 3.182, 4: 2.776, 5: 2.571, 6: 2.447, 7: 2.365, 8: 2.306, 9: 2.262, 10: 2.228}


def round_medians(r):
    """The median of each round's pairs of a run's paired ratio to Embree, in round order."""
    p = (r or {}).get("paired_ratio") or {}
    out, at = [], 0
    for rd in (r or {}).get("rounds") or []:
        k = rd.get("pairs", 0)
        xs = sorted(p.get("samples", [])[at:at + k])
        at += k
        if xs:
            n = len(xs)
            out.append(xs[n // 2] if n % 2 else 0.5 * (xs[n // 2 - 1] + xs[n // 2]))
    return out


def quotient_rounds(ra, rb):
    """a ÷ b of two engines' paired ratios to Embree, round by round: round i of every job of a run ran in the
    same pass over the jobs, so each round's quotient leaves out what moved both. The mean of the rounds' log
    quotients over the rounds both ran, with Student's t 95 % interval; from the two intervals' bounds
    ([`quotient`]) when fewer than two rounds are common."""
    a, b = round_medians(ra), round_medians(rb)
    n = min(len(a), len(b))
    if n < 2:
        return quotient(paired(ra), paired(rb))
    return log_mean_ci([math.log(a[i] / b[i]) for i in range(n)])


def log_mean_ci(logs):
    """exp of the mean of `logs` with Student's t 95 % interval, as (estimate, lo, hi, exact); None below two."""
    n = len(logs)
    if n < 2:
        return None
    m = sum(logs) / n
    sd = math.sqrt(sum((x - m) ** 2 for x in logs) / (n - 1))
    h = T95.get(n - 1, 1.96) * sd / math.sqrt(n)
    return math.exp(m), math.exp(m - h), math.exp(m + h), True


def met(c, bound, above=True):
    """Whether the whole interval is past the bound ("yes"), only the estimate ("estimate only"), or neither."""
    if c is None:
        return "–"
    lo, est, hi = c[1], c[0], c[2]
    if above:
        return "yes" if lo >= bound else ("estimate only" if est >= bound else "**no**")
    return "yes" if hi <= bound else ("estimate only" if est <= bound else "**no**")


def wide(d):
    """bvh8 at least 1.1× and bvh4 at least 1.0× Embree's speed."""
    recs = records(d)
    t = by_scene(recs)
    rows = []
    for s in scenes_of(t):
        b8, b4 = inverse(paired(t[s].get("bvh8"))), inverse(paired(t[s].get("bvh4")))
        rows.append([s, fmt_ci(b8), met(b8, 1.1), fmt_ci(b4), met(b4, 1.0)])
    return md(["scene", "bvh8 speed ÷ Embree's", "≥ 1.1", "bvh4 speed ÷ Embree's", "≥ 1.0"], rows) + failures(recs)


def tinybvh(d):
    """bvh8 against tinybvh's fastest layout, both timed in pairs with Embree."""
    recs = records(d)
    t = by_scene(recs)
    rows = []
    for s in scenes_of(t):
        layouts = {e: paired(r) for e, r in t[s].items() if e.startswith("tinybvh")}
        layouts = {e: c for e, c in layouts.items() if c}
        if not layouts or "bvh8" not in t[s]:
            continue
        fastest = min(layouts, key=lambda e: layouts[e][0])
        agree = lambda r: f"{(r.get('check') or {}).get('hit_agreement', float('nan')):.6f}"
        b8 = paired(t[s]["bvh8"])
        q = quotient_rounds(t[s][fastest], t[s]["bvh8"])
        rows.append([s, fmt_ci(b8), fastest.replace("tinybvh[layout=", "").rstrip("]"), fmt_ci(layouts[fastest]),
                     fmt_ci(q), met(q, 1.0), agree(t[s][fastest]), agree(t[s]["bvh8"])])
    return md(["scene", "bvh8 time ÷ Embree's", "tinybvh's fastest layout", "its time ÷ Embree's",
               "bvh8 speed ÷ tinybvh's", "≥ 1.0", "its hits as Embree's", "bvh8's hits as Embree's"],
              rows) + failures(recs)


def in_core(d):
    """breadth-first at its defaults in memory: peak RSS against bvh8's, trace time against the grid's."""
    recs = records(d)
    t = by_scene(recs)
    rows = []
    for s in scenes_of(t):
        bf, b8, g = t[s].get("breadth-first"), t[s].get("bvh8"), t[s].get("grid")
        if not (bf and b8 and g):
            continue
        rss = bf["peak_rss_bytes"] / b8["peak_rss_bytes"]
        q = quotient_rounds(bf, g)
        rows.append([s, f"{bf['peak_rss_bytes'] / 2**20:.1f} / {b8['peak_rss_bytes'] / 2**20:.1f}", f"{rss:.2f}",
                     "yes" if rss <= 2 else "**no**", fmt_ci(q), met(q, 1.5, above=False)])
    return md(["scene", "peak RSS MiB, breadth-first / bvh8", "ratio", "≤ 2", "trace time ÷ the grid's", "≤ 1.5"],
              rows) + failures(recs)


def over_processes(dirs, scene, engine):
    """One figure from runs of one process each (a binary without rounds): the mean of their pairs' medians on
    the log scale, with Student's t 95 % interval over the processes."""
    meds = []
    for d in dirs:
        r = by_scene(records(d)).get(scene, {}).get(engine)
        if r and r.get("paired_ratio"):
            meds.append(math.log(r["paired_ratio"]["median"]))
    return log_mean_ci(meds)


def grid_then(now, thens):
    """The grid against the grid of the targets' day, each timed in pairs with Embree by its own binary: now over
    the rounds of one run, then over one process per run."""
    a = by_scene(records(now))
    first = by_scene(records(thens[0]))
    rows = []
    for s in scenes_of(a):
        n, o = a[s].get("grid"), (first.get(s) or {}).get("grid")
        if not (n and o):
            continue
        old = over_processes(thens, s, "grid")
        q = quotient(old, paired(n))
        keys = ["primitive_tests", "cells_visited", "mailbox_skips", "box_tests", "shadow_cache_hits"]
        same = all(n["counters"].get(k) == o["counters"].get(k) for k in keys)
        rows.append([s, fmt_ci(old), fmt_ci(paired(n)), fmt_ci(q), met(q, 1.3), "yes" if same else "**no**"])
    return md(["scene", "then: time ÷ Embree's", "now: time ÷ Embree's", "speed-up", "≥ 1.3", "same counters"],
              rows) + failures(records(now))


def two_threads(d):
    """Every engine's speed-up at two threads (the median of its paired-threads samples; ✗ below 1.8), and the
    CPU seconds its pool's threads used at two threads over those at one (medians): 1.00 when the split trace cost
    no more CPU time."""
    def cell(r):
        ts = r.get("thread_scaling")
        if not ts:
            return "–"
        c = pairs_ci(r, ts["speedup"])
        growth = ts["threads_cpu_s"]["median"] / max(ts["one_thread_cpu_s"]["median"], 1e-12)
        return fmt_ci(c) + ("" if c[0] >= 1.8 else " ✗") + f" (CPU {growth:.2f})"
    recs, engines, rows = per_engine(d, cell)
    return md(["scene"] + engines, rows) + failures(recs)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "out/benchmarks"
    parts = [("speed", speed), ("speed", memory), ("build", build), ("grid", grid),
             ("wide", wide), ("tinybvh", tinybvh), ("in-core", in_core), ("two-threads", two_threads)]
    for sub, f in parts:
        d = os.path.join(out, sub)
        if records(d):
            print(f"## {f.__name__} ({sub}: {env_line(d)})\n\n{f(d)}\n")
    now = os.path.join(out, "grid-now")
    thens = sorted(os.path.join(out, d) for d in os.listdir(out) if d.startswith("grid-then")) \
        if os.path.isdir(out) else []
    if records(now) and thens and records(thens[0]):
        print(f"## grid_then (grid-now: {env_line(now)}; grid-then: {env_line(thens[0])}, {len(thens)} processes)"
              f"\n\n{grid_then(now, thens)}\n")
    if os.path.isdir(os.path.join(out, "ooc")):
        print(f"## ooc\n\n{ooc(os.path.join(out, 'ooc'))}\n")
    p = os.path.join(out, "goals", "kimura-simd.json")
    if os.path.exists(p):
        j = json.load(open(p))
        v = j["invocation"]
        dirty = " (with uncommitted changes)" if v.get("dirty") else ""
        print(f"## goals ({v['date'][:16].replace('T', ' ')} UTC, commit {v['commit'][:10]}{dirty}, {v['machine']})"
              f"\n\n{goals(j)}\n")


if __name__ == "__main__":
    main()
