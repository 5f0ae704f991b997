import json,sys,collections
for f in sys.argv[1:]:
    rows=[json.loads(l) for l in open(f)]
    t={}
    for r in rows:
        t[(r['engine'],r['scene']['name'],r['threads'])]=r['time_s']['trace']['median']
    scenes=sorted({k[1] for k in t})
    engines=['embree','bvh4','bvh8','grid']
    print(f)
    print('scene     '+''.join(f'{e:>9}' for e in engines))
    for s in scenes:
        print(f'{s:10}'+''.join(f"{t[(e,s,1)]/t[(e,s,2)]:9.2f}" for e in engines if (e,s,2) in t))
