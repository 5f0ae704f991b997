#!/usr/bin/env python3
"""Issue 20 acceptance 5, session 15: peak RSS of the chunked wavefront against 3 x structure bytes + 16 MiB, and the
trace time of the chunked wavefront (default --chunk 4096) against the whole-generation wavefront (--chunk 0, the
renderer as it was when the issue was filed) in alternating renders of the same binary.
Usage: a5.py RTBENCH OUT.jsonl [ROUNDS]"""
import json, subprocess, sys
B, OUT = sys.argv[1], sys.argv[2]
rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 5
scenes = ['balls', 'gears', 'mount', 'rings', 'teapot', 'tetra', 'tree']
out = open(OUT, 'w')
for sc in scenes:
    for eng in ['bvh8', 'bvh4', 'grid']:
        for r in range(rounds):
            for chunk in (['4096', '0'] if r % 2 == 0 else ['0', '4096']):
                j = json.loads(subprocess.run([B, 'render', '--scene', sc, '--engine', eng, '--threads', '1', '--size', '512',
                                               '--chunk', chunk, '--json'], capture_output=True, text=True, check=True).stdout)
                row = {'scene': sc, 'engine': eng, 'round': r, 'chunk': int(chunk), 'trace_s': j['time_s']['trace'],
                       'peak_rss_bytes': j['memory']['peak_rss_bytes'], 'structure_bytes': j['memory']['structure_bytes'],
                       'sha256': j['image']['sha256'], 'counters': j['counters']}
                out.write(json.dumps(row) + '\n'); out.flush()
