#!/bin/bash
# Issue 20, session 12, helper a: second quiet window (both cores free). ≤ ~4 minutes.
# Uses only binaries already built under this folder; writes only under this folder and stdout.
B=WINDOW
O=$B/out2
mkdir -p $O
cd $B
START=$SECONDS
left() { echo $(( 300 - (SECONDS - START) )); }
echo "window2 start $(date -u +%H:%M:%S) nproc $(nproc) load $(cut -d' ' -f1-3 /proc/loadavg) steal $(awk '/^cpu /{print $9}' /proc/stat)"
echo "== 1. acceptance 4: engine_builds balls --rounds 5, base (main 1327c78) and branch (f9326ae) alternated, 3 each"
for bin in new base new base new base; do
  [ $(left) -lt 200 ] && { echo "skip $bin: budget"; continue; }
  echo "-- engine_builds-$bin"
  timeout 30 ./engine_builds-$bin balls --rounds 5 | grep -E "median|load"
done
echo "== 2. Embree's threads off CPU? perf stat (software events) of a two-thread render, Embree and bvh8"
for sc in balls rings; do for e in embree bvh8; do
  [ $(left) -lt 120 ] && continue
  echo "-- $e $sc threads 2"
  perf stat -e task-clock,context-switches,cpu-migrations,page-faults ./rtbench-final render --scene $sc --engine $e --threads 2 --size 512 2>&1 | grep -E "rays in|task-clock|context-switches|cpu-migrations|page-faults|elapsed"
done; done
echo "== 3. per-band thread and CPU seconds (RTBENCH_BANDS=1), Embree and bvh8 on balls4, 2 threads"
for e in embree bvh8; do
  [ $(left) -lt 90 ] && continue
  RTBENCH_BANDS=1 ./rtbench-final render --scene balls --engine $e --threads 2 --size 512 2>&1 | awk -v e=$e '/^band/ {th=$6; cpu[th]+=$NF; n[th]++} /rays in/ {print e": "$0} END {for (t in cpu) printf "%s thread %s bands %d cpu_s %.4f\n", e, t, n[t], cpu[t]}'
done
echo "== 4. paired speed-up again, Embree and bvh8, 4 scenes, --paired-threads 7"
T=$(( $(left) - 10 )); [ $T -gt 100 ] && T=100
[ $T -gt 20 ] && timeout $T ./rtbench-final run --engines embree,bvh8 --scenes balls,gears,mount,rings --threads 2 --repeat 1 --paired-threads 7 --no-check --out $O/pt 2>&1 | grep -c ok
[ -f $O/pt/results.jsonl ] && python3 - $O/pt/results.jsonl <<'PY'
import json,sys
for l in open(sys.argv[1]):
    r=json.loads(l); s=r.get('thread_scaling')
    if not s: print(r['key'], r['status']); continue
    p=s['speedup']; busy=s['threads_cpu_s']['median']/(2*s['threads_s']['median'])
    print(f"{r['engine']:7} {r['scene']['name']:9} speedup median {p['median']:.3f} min {p['min']:.3f} max {p['max']:.3f} n {len(p['samples'])} cpu x1 {s['threads_cpu_s']['median']/s['one_thread_cpu_s']['median']:.3f} busy {busy:.3f}")
PY
echo "window2 end $(date -u +%H:%M:%S) elapsed $((SECONDS-START)) s load $(cut -d' ' -f1-3 /proc/loadavg) steal $(awk '/^cpu /{print $9}' /proc/stat)"
