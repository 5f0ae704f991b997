import json,sys
# hashes.py JSONL...: engine scene image-sha256 (first 16) per row, sorted
out=set()
for f in sys.argv[1:]:
    for l in open(f):
        j=json.loads(l)
        out.add((j['engine'], j['scene']['name'], j.get('image_sha256','')[:16]))
for r in sorted(out): print(*r)
