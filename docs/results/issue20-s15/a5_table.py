#!/usr/bin/env python3
"""Table of a5.py's rows: peak RSS (chunked) against 3 x structure + 16 MiB, and the chunked trace time over the
whole-generation one (median of the rounds' ratios). Usage: a5_table.py ROWS.jsonl"""
import json, sys, statistics as st
rows = [json.loads(l) for l in open(sys.argv[1])]
keys = sorted({(r['scene'], r['engine']) for r in rows}, key=lambda k: (k[0], ['bvh8', 'bvh4', 'grid'].index(k[1])))
MiB = 1 << 20
print('| scene | engine | structure MiB | target MiB | peak RSS MiB, chunked, max | holds | trace chunked / whole, median (min-max) | same image |')
print('|---|---|---:|---:|---:|---|---|---|')
for k in keys:
    rs = [r for r in rows if (r['scene'], r['engine']) == k]
    c = [r for r in rs if r['chunk'] == 4096]; w = [r for r in rs if r['chunk'] == 0]
    target = 3 * c[0]['structure_bytes'] + 16 * MiB
    peak = max(r['peak_rss_bytes'] for r in c)
    ratios = sorted(a['trace_s'] / b['trace_s'] for a, b in zip(sorted(c, key=lambda r: r['round']), sorted(w, key=lambda r: r['round'])))
    same = len({r['sha256'] for r in rs}) == 1
    print(f"| {k[0]} | {k[1]} | {c[0]['structure_bytes']/MiB:.2f} | {target/MiB:.2f} | {peak/MiB:.2f} | {'yes' if peak <= target else 'NO'} | "
          f"{st.median(ratios):.3f} ({ratios[0]:.3f}-{ratios[-1]:.3f}) | {'yes' if same else 'NO'} |")
