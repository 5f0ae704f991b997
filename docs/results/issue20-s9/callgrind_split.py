#!/usr/bin/env python3
"""Issue 20, session 9: where one traversal entry point's instructions go.

Usage: callgrind_split.py CALLGRIND_OUT BINARY FUNCTION RAYS 'name=lines,...;name=lines'
CALLGRIND_OUT from `valgrind --tool=callgrind --dump-instr=yes`; FUNCTION the entry point's
name suffix (e.g. avx8_closest_impl); RAYS the rays it traced (for per-ray figures); the last
argument maps traverse.rs line ranges to categories (counters, ordering, ...). Each
instruction's self cost is attributed by its inline chain (addr2line -i): ray set-up
(ray_setup, SlabRay, WatertightRay, prepare), leaf triangle tests (triangle_simd), node box
tests (box_test), child ordering/stack (prefetch, child_addr), else by the traverse.rs line.
An optimising compiler's line tables are approximate: the split is a guide, not an exact count.
"""
import sys, re, subprocess, collections
cg, binary_, fn, nrays, lines = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), sys.argv[5]
binary, fname = binary_, fn
names = {}
cur_fn = None
costs = collections.Counter()
addr = 0; line = 0
skip_next = False
def sub(tok, prev):
    if tok == '*': return prev
    if tok.startswith('0x'): return int(tok, 16)
    if tok.startswith('+'): return prev + int(tok[1:], 16 if tok[1:].startswith('0x') else 10) if not tok[1:].startswith('0x') else prev+int(tok[3:],16)
    if tok.startswith('-'): return prev - int(tok[1:])
    return int(tok)
for raw in open(cg):
    l = raw.rstrip('\n')
    if not l: continue
    m = re.match(r'^(c?fn)=\((\d+)\)(?: (.*))?$', l)
    if m:
        if m.group(3): names[m.group(2)] = m.group(3)
        if m.group(1) == 'fn': cur_fn = names.get(m.group(2))
        continue
    if l.startswith('calls='):
        skip_next = True; continue
    if l[0] in '0123456789+-*':
        toks = l.split()
        addr = sub(toks[0], addr)
        if len(toks) > 1:
            line = sub(toks[1], line) if toks[1] != '*' else line
        if skip_next:
            skip_next = False; continue
        if cur_fn and cur_fn.endswith(fname) and len(toks) >= 3:
            costs[addr] += int(toks[2])
        continue
# lines: traverse.rs line ranges "setup=a-b,..;counters=..." for the binary's source
ranges = {}
for part in lines.split(';'):
    k, v = part.split('=')
    for r in v.split(','):
        a, _, b = r.partition('-'); ranges.setdefault(k, []).append((int(a), int(b or a)))
def linecat(n):
    if n is None: return 'loop (no line)'
    for k, rs in ranges.items():
        for a, b in rs:
            if a <= n <= b: return k
    return 'loop (no line)'
addrs = sorted(costs)
out = subprocess.run(['addr2line', '-i', '-f', '-C', '-a', '-e', binary] + [hex(a) for a in addrs], capture_output=True, text=True).stdout
chains = {}; cur = None; L = out.split('\n'); i = 0
while i < len(L):
    l = L[i]
    if l.startswith('0x'): cur = int(l, 16); chains[cur] = []; i += 1; continue
    if cur is not None and i + 1 < len(L): chains[cur].append((l, L[i+1])); i += 2; continue
    i += 1
CATS = [(r'ray_setup|SlabRay|WatertightRay|is_traceable|::prepare|triangle_setup', 'ray set-up'),
        (r'edge_in_f64|triangle_simd|LaneHits|PacketKernel|PairKernel|pair_hits|leaf_packets', 'leaf triangle tests'),
        (r'box_test', 'node box tests'),
        (r'prefetch|child_addr', 'child ordering/stack')]
cat = collections.Counter()
for a in addrs:
    ch = chains.get(a, [])
    funcs = ' | '.join(f + ' @ ' + loc.split('/')[-1] for f, loc in ch)
    c = None
    tl = next((loc.split('/')[-1].split(' ')[0] for f, loc in ch if 'traverse.rs' in loc), None)
    n = int(tl.split(':')[1]) if tl and tl.split(':')[1].isdigit() else None
    if linecat(n) == 'counters': c = 'counters'
    if c is None:
        for k, v in CATS:
            if re.search(k, funcs): c = v; break
    if c is None: c = linecat(n)
    cat[c] += costs[a]
tot = sum(costs.values())
print(f'{cg} {fn}: {tot:,} ({tot/nrays:.0f} per ray)')
for c, v in cat.most_common():
    print(f'  {c:24s} {v/nrays:7.0f} per ray  {100*v/tot:5.1f}%')
