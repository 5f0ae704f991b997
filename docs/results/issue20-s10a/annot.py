#!/usr/bin/env python3
# annot.py CG BINARY FNSUFFIX [min_count]: disassembly of the function with callgrind per-instruction counts
import sys, re, subprocess, collections
cg, binary, fname = sys.argv[1:4]
mn = int(sys.argv[4]) if len(sys.argv) > 4 else 1
names = {}; cur_fn = None; costs = collections.Counter(); addr = 0; skip = False
def sub(tok, prev):
    if tok == '*': return prev
    if tok.startswith('0x'): return int(tok, 16)
    if tok.startswith('+'): t=tok[1:]; return prev + (int(t,16) if t.startswith('0x') else int(t))
    if tok.startswith('-'): t=tok[1:]; return prev - (int(t,16) if t.startswith('0x') else int(t))
    return int(tok)
for raw in open(cg):
    l = raw.rstrip('\n')
    if not l: continue
    m = re.match(r'^(c?fn)=\((\d+)\)(?: (.*))?$', l)
    if m:
        if m.group(3): names[m.group(2)] = m.group(3)
        if m.group(1) == 'fn': cur_fn = names.get(m.group(2))
        continue
    if l.startswith('calls='): skip = True; continue
    if l[0] in '0123456789+-*':
        toks = l.split(); addr = sub(toks[0], addr)
        if skip: skip = False; continue
        if cur_fn and cur_fn.endswith(fname) and len(toks) >= 3: costs[addr] += int(toks[2])
a0, a1 = min(costs), max(costs)
out = subprocess.run(['objdump','-d','--no-show-raw-insn','-C',f'--start-address={a0:#x}',f'--stop-address={a1+16:#x}',binary],capture_output=True,text=True).stdout
tot = sum(costs.values())
print(f'total {tot:,}')
for l in out.split('\n'):
    m = re.match(r'^\s*([0-9a-f]+):\s*(.*)$', l)
    if not m: continue
    a = int(m.group(1),16); c = costs.get(a,0)
    if c >= mn: print(f'{c:12,} {a:x}: {m.group(2)}')
