import json,sys
# ratios_var.py DIR: Embree time / engine time (1/paired_ratio median, min-max) per engine label (variants included) and scene, with image sha256
rows={}
scenes=[]
for l in open(sys.argv[1]+'/results.jsonl'):
    j=json.loads(l)
    if j['engine']=='embree': continue
    lab=j['engine']+''.join(f':{k}={v}' for k,v in sorted((j.get('settings') or {}).items()))
    s=j['scene']['name']
    if s not in scenes: scenes.append(s)
    p=j.get('paired_ratio')
    rows[(lab,s)]=(p,j.get('image_sha256','')[:12], j.get('counters',{}))
labs=sorted({k[0] for k in rows})
print('| engine | '+' | '.join(scenes)+' |')
for e in labs:
    cells=[]
    for s in scenes:
        p,h,c=rows.get((e,s),(None,'',{}))
        cells.append('—' if not p else f"{1/p['median']:.2f} ({1/p['max']:.2f}–{1/p['min']:.2f}) {h}")
    print(f"| {e} | "+" | ".join(cells)+" |")
