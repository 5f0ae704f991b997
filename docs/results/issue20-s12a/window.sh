#!/bin/bash
# Issue 20, session 12, helper a: measurements for the quiet window (both cores free).
# At most ~5.5 minutes: every step has its own timeout and is skipped when the budget is spent.
# Uses only binaries already built under this folder; writes only under this folder (and stdout).
B=WINDOW
O=$B/out
mkdir -p $O
cd $B
START=$SECONDS
left() { echo $(( 330 - (SECONDS - START) )); }
echo "window start $(date -u +%H:%M:%S) nproc $(nproc) load $(cut -d' ' -f1-3 /proc/loadavg)"

echo "== 1. acceptance 4: engine_builds balls --rounds 5 (balls4 tessellated), base (main 1327c78) then branch, twice"
for bin in base new base new; do
  [ $(left) -lt 250 ] && { echo "skip $bin: budget"; continue; }
  echo "-- engine_builds-$bin"
  timeout 30 ./engine_builds-$bin balls --rounds 5
  echo "load $(cut -d' ' -f1-3 /proc/loadavg)"
done

echo "== 2. acceptance 3: paired speed-up over one thread, 512², --paired-threads (one process per run)"
T=$(( $(left) - 150 )); [ $T -gt 120 ] && T=120
echo "-- embree,bvh4,bvh8 standard --paired-threads 5 (timeout $T s)"
[ $T -gt 20 ] && timeout $T ./rtbench-new run --engines embree,bvh4,bvh8 --scenes standard --threads 2 --repeat 1 --paired-threads 5 --no-check --out $O/pt3 2>&1 | grep -v "^\s*$"
echo "load $(cut -d' ' -f1-3 /proc/loadavg)"
T=$(( $(left) - 45 )); [ $T -gt 110 ] && T=110
echo "-- grid standard --paired-threads 3 (timeout $T s)"
[ $T -gt 20 ] && timeout $T ./rtbench-new run --engines grid --scenes standard --threads 2 --repeat 1 --paired-threads 3 --no-check --out $O/ptg 2>&1 | grep -v "^\s*$"
echo "load $(cut -d' ' -f1-3 /proc/loadavg)"
for d in pt3 ptg; do
  [ -f $O/$d/results.jsonl ] && python3 - $O/$d/results.jsonl <<'PY'
import json,sys
for l in open(sys.argv[1]):
    r=json.loads(l); s=r.get('thread_scaling')
    if not s: print(r['key'], r['status'], r.get('reason')); continue
    p=s['speedup']
    print(f"{r['engine']:7} {r['scene']['name']:9} speedup median {p['median']:.3f} min {p['min']:.3f} max {p['max']:.3f} n {len(p['samples'])}  t1 {s['one_thread_s']['median']:.4f} t2 {s['threads_s']['median']:.4f}  cpu1 {s['one_thread_cpu_s']['median']:.4f} cpu2 {s['threads_cpu_s']['median']:.4f}  samples {' '.join(f'{x:.3f}' for x in p['samples'])}")
PY
done

echo "== 3. issue 2 (Embree's scaling): one-thread trace alone, then two independent one-thread processes at once (one per core)"
one() { ./rtbench-new run-one --scene $1 --engine $2 --threads 1 --repeat 5 --size 512 --no-check 2>/dev/null | python3 -c "import json,sys; r=json.load(sys.stdin); t=r['time_s']['trace']; print(f\"trace median {t['median']:.4f} min {t['min']:.4f} max {t['max']:.4f}\")"; }
for sc in balls rings gears teapot; do for eng in embree bvh8; do
  [ $(left) -lt 12 ] && { echo "skip $eng $sc: budget"; continue; }
  a=$(taskset -c 1 bash -c "$(declare -f one); cd $B; one $sc $eng")
  taskset -c 0 bash -c "$(declare -f one); cd $B; one $sc $eng" > $O/p0 &
  taskset -c 1 bash -c "$(declare -f one); cd $B; one $sc $eng" > $O/p1
  wait
  echo "$eng $sc alone: $a | together cpu0: $(cat $O/p0) | cpu1: $(cat $O/p1)"
done; done
echo "window end $(date -u +%H:%M:%S) elapsed $((SECONDS-START)) s load $(cut -d' ' -f1-3 /proc/loadavg)"
