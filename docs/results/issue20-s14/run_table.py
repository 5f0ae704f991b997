#!/usr/bin/env python3
"""Speed-up table of `rtbench run --paired-threads` result folders: engine, scene, speed-up median (min–max),
CPU time at two threads over one, share of 2 × wall the pool's threads were on a CPU. Usage: run_table.py DIR..."""
import json, os, sys
for d in sys.argv[1:]:
    for l in open(os.path.join(d, 'results.jsonl')):
        r = json.loads(l); s = r.get('thread_scaling')
        if not s:
            print(f"{d} {r['key']} {r['status']}"); continue
        p = s['speedup']
        busy = s['threads_cpu_s']['median'] / (2 * s['threads_s']['median'])
        cpu = s['threads_cpu_s']['median'] / s['one_thread_cpu_s']['median']
        print(f"| {os.path.basename(d)} | {r['engine']} | {r['scene']['name']} | {p['median']:.2f} ({p['min']:.2f}–{p['max']:.2f}) | {cpu:.2f} | {busy:.2f} |")
