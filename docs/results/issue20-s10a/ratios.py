import json,sys
# ratios.py DIR...: Embree time / engine time (1 / paired_ratio), median (min-max) of the pairs, per scene
scenes=['balls4','gears4','mount6','rings7','teapot12','tetra6','tree11']
for d in sys.argv[1:]:
    rows={}
    for l in open(d+'/results.jsonl'):
        j=json.loads(l)
        if j['engine']=='embree': continue
        p=j.get('paired_ratio')
        rows[(j['engine'],j['scene']['name'])]=(p, j.get('image_sha256','')[:12])
    print(d)
    for e in ['bvh8','bvh4']:
        cells=[]
        for s in scenes:
            p,h=rows.get((e,s),(None,''))
            cells.append('—' if not p else f"{1/p['median']:.2f} ({1/p['max']:.2f}–{1/p['min']:.2f})")
        print(f"| {e} | "+" | ".join(cells)+" |")
