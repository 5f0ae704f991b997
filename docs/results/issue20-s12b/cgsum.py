import re,sys,subprocess
out=subprocess.run(['callgrind_annotate','--inclusive=yes','--threshold=100',sys.argv[1]],capture_output=True,text=True).stdout
halve = len(sys.argv)>2
for line in out.splitlines():
    m=re.search(r'(fma4_closest_impl|fma4_any_impl|avx8_closest_impl|avx8_any_impl|rtcIntersect1|rtcOccluded1) \[',line)
    if not m: continue
    nums=[int(x.replace(',','')) for x in re.findall(r'([\d,]+) \(',line)]
    while len(nums)<9: nums.append(0)
    f=m.group(1)
    d=2 if (f=='avx8_closest_impl' and halve) else 1
    ir,dr,dw,i1,d1r,d1w,il,dlr,dlw=[x/d for x in nums[:9]]
    print(f"{f:20s} Ir {ir/1e6:8.2f}M  Dr {dr/1e6:7.2f}M  D1 miss {(d1r+d1w)/1e3:8.1f}k ({100*(d1r+d1w)/max(dr+dw,1):.2f}%)  LL miss {(dlr+dlw)/1e3:7.1f}k")
