#!/usr/bin/env python3
"""Summarise RTBENCH_SCHED(=bands) stderr of `rtbench run-one ... --paired-threads N`: one row per render
(threads, wall, per-thread run / run-queue wait / off-CPU seconds, switches, faults, migrations, the CPUs'
idle and steal seconds, and from the band lines the seconds both threads spent in bands on the same CPU).
Usage: sched_summary.py FILE.sched [...]"""
import sys

def kv(words):
    return {words[i]: words[i + 1] for i in range(0, len(words) - 1)}

def renders(path):
    bands, cpus, threads = [], [], []
    out = []
    for line in open(path):
        w = line.split()
        if not w or w[0] != 'sched':
            continue
        if w[1] == 'band':
            if threads:
                out.append((bands, cpus, threads)); bands, cpus, threads = [], [], []
            bands.append((int(w[4]), int(w[6]), int(w[7]), float(w[9]), float(w[11])))
        elif w[1] == 'cpu':
            if threads:
                out.append((bands, cpus, threads)); bands, cpus, threads = [], [], []
            d = kv(w[3:]); d['cpu'] = int(w[2]); cpus.append(d)
        elif w[1] == 'thread':
            d = kv(w[2:]); threads.append(d)
    if threads:
        out.append((bands, cpus, threads))
    return out

def same_cpu_overlap(bands):
    """Seconds during which bands of thread 0 and thread 1 overlapped in time, in total and while both
    bands started and ended on one and the same CPU."""
    a = [b for b in bands if b[0] == 0]
    b_ = [b for b in bands if b[0] == 1]
    both = same = 0.0
    for x in a:
        for y in b_:
            o = min(x[4], y[4]) - max(x[3], y[3])
            if o > 0:
                both += o
                if x[1] == x[2] == y[1] == y[2]:
                    same += o
    return both, same

def main():
    for path in sys.argv[1:]:
        rs = renders(path)
        print(f'# {path}: {len(rs)} renders')
        print('  i thr   wall_s  run_s(sum) wait_s(sum) off_s(sum)  busy  vcsw nvcsw minflt migr  idle_s steal_s  both_in_bands_s same_cpu_s  cpus(thread:last)')
        for i, (bands, cpus, th) in enumerate(rs):
            wall = float(th[0]['wall_s'])
            run = sum(float(t['run_s']) for t in th)
            wait = sum(float(t['runq_wait_s']) for t in th)
            off = sum(float(t['off_s']) for t in th)
            busy = run / (len(th) * wall)
            vcsw = sum(int(t['vcsw']) for t in th); nvcsw = sum(int(t['nvcsw']) for t in th)
            minflt = sum(int(t['minflt']) for t in th); migr = sum(int(t['migrations']) for t in th)
            idle = sum(float(c['idle_s']) for c in cpus); steal = sum(float(c['steal_s']) for c in cpus)
            both, same = same_cpu_overlap(bands) if len(th) == 2 else (0.0, 0.0)
            last = ','.join(f"{j}:{t['cpu']}" for j, t in enumerate(th))
            print(f'{i:3} {len(th):3} {wall:8.4f} {run:10.4f} {wait:10.4f} {off:10.4f} {busy:5.2f} {vcsw:5} {nvcsw:5} {minflt:6} {migr:4} {idle:7.2f} {steal:7.2f} {both:15.4f} {same:10.4f}  {last}')

if __name__ == "__main__":
    main()
