#!/usr/bin/env python3
"""One row per run of window.sh: the paired speed-up (run-one's thread_scaling) and, over the five two-thread
renders of the pairs (renders 4, 5, 8, 9, 12 of the run: 0 and 1 are the untimed and timed two-thread renders, 2
the one-thread pool's untimed one, then the pairs alternate which goes first), medians of each thread's share of
the wall time on a CPU, waiting on a run queue and off (asleep or stolen), switches, migrations, the seconds
both threads ran bands on one and the same CPU (from the band lines) and the CPUs' idle and steal seconds.
Usage: window_table.py DIR"""
import json, os, statistics as st, sys
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from sched_summary import renders, same_cpu_overlap

d = sys.argv[1]
print('| run | engine | scene | speed-up median (min–max) | CPU share of 2 × wall (json) | on CPU | run-queue wait | off | vcsw | nvcsw | migrations | both threads in bands on one CPU, s / wall | CPUs idle s / wall | steal s | one-thread render: on CPU share |')
print('|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|')
for f in sorted(os.listdir(d)):
    if not f.endswith('.json'):
        continue
    tag, eng, scene = f[:-5].split('-', 2)[0] + '-' + f[:-5].split('-', 2)[1], f[:-5].split('-')[2], f[:-5].split('-')[3]
    try:
        r = json.load(open(os.path.join(d, f)))
    except Exception:
        print(f'| {tag} | {eng} | {scene} | failed |'); continue
    s = r['thread_scaling']; sp = s['speedup']
    busy = s['threads_cpu_s']['median'] / (2 * s['threads_s']['median'])
    rs = renders(os.path.join(d, f[:-5] + '.sched'))
    two = [rs[i] for i in (4, 5, 8, 9, 12) if i < len(rs) and len(rs[i][2]) == 2]
    one = [rs[i] for i in (3, 6, 7, 10, 11) if i < len(rs) and len(rs[i][2]) == 1]
    def med(fn, xs):
        return st.median(fn(x) for x in xs) if xs else float('nan')
    def share(key):
        return lambda x: sum(float(t[key]) for t in x[2]) / (len(x[2]) * float(x[2][0]['wall_s']))
    def total(key):
        return lambda x: sum(float(t[key]) for t in x[2])
    same = med(lambda x: same_cpu_overlap(x[0])[1] / float(x[2][0]['wall_s']), two)
    idle = med(lambda x: sum(float(c['idle_s']) for c in x[1]) / float(x[2][0]['wall_s']), two)
    steal = med(lambda x: sum(float(c['steal_s']) for c in x[1]), two)
    print(f"| {tag} | {eng} | {scene} | {sp['median']:.2f} ({sp['min']:.2f}–{sp['max']:.2f}) | {busy:.2f} | "
          f"{med(share('run_s'), two):.2f} | {med(share('runq_wait_s'), two):.2f} | {med(share('off_s'), two):.2f} | "
          f"{med(total('vcsw'), two):.0f} | {med(total('nvcsw'), two):.0f} | {med(total('migrations'), two):.0f} | "
          f"{same:.2f} | {idle:.2f} | {steal:.2f} | {med(share('run_s'), one):.2f} |")
