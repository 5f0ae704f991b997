#!/usr/bin/env python3
"""Issue 20, session 15: do the slow two-thread traces coincide with the host taking the CPUs (steal)? Renders the
same scene N times at two threads with RTBENCH_SCHED=1 and prints, per render, the trace time, the pool threads'
run time over the wall time, and the CPUs' steal seconds. Usage: steal.py RTBENCH SCENE ENGINE N"""
import json, subprocess, sys
B, scene, engine, n = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
for i in range(n):
    p = subprocess.run([B, 'render', '--scene', scene, '--engine', engine, '--threads', '2', '--size', '512', '--json'],
                       capture_output=True, text=True, env={'RTBENCH_SCHED': '1', 'PATH': '/usr/bin:/bin'}, check=True)
    j = json.loads(p.stdout)
    steal = sum(float(l.split('steal_s ')[1].split()[0]) for l in p.stderr.splitlines() if l.startswith('sched cpu '))
    runs = [(float(l.split('run_s ')[1].split()[0]), float(l.split('wall_s ')[1].split()[0]), float(l.split('runq_wait_s ')[1].split()[0]))
            for l in p.stderr.splitlines() if l.startswith('sched thread ')]
    print(f"{i} trace_ms {j['time_s']['trace']*1e3:.1f} run/wall {sum(r for r,_,_ in runs)/sum(w for _,w,_ in runs):.3f} "
          f"runq_ms {sum(q for _,_,q in runs)*1e3:.1f} steal_ms {steal*1e3:.0f}", flush=True)
