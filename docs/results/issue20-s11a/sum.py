# sum.py FILE...: M instructions of the packet, single-ray and Embree entry points in cg.sh's TAG-SCENE.txt files
# (pk_: packet.rs kernels; bvh8 single's eye count is two traces in the bench).
import sys,re
# print M instructions for key entry points from callgrind_annotate summary lines
for f in sys.argv[1:]:
    out={}
    for line in open(f):
        m=re.match(r'\s*([\d,]+) \([^)]*\)\s+(\S+):(\S+)',line)
        if not m: continue
        n=int(m.group(1).replace(',',''))
        fn=m.group(2)+':'+m.group(3)
        for key in ['packet::x86::closest_impl','packet::x86::any_impl','avx8_closest_impl','avx8_any_impl','rtcIntersect1','rtcIntersect8','rtcIntersect16','rtcOccluded1','rtcOccluded8','rtcOccluded16']:
            if fn.endswith(key) and key not in out and ('dispatch.rs:' in fn or 'packet.rs:' in fn or '???:' in fn):
                out[key]=n
    print(f, ' '.join(f'{k.split("::")[-1] if "packet" not in k else "pk_"+k.split("::")[-1]}={v/1e6:.2f}' for k,v in out.items()))
