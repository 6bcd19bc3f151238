import numpy as np, sys
a=np.load(sys.argv[1],allow_pickle=False); b=np.load(sys.argv[2],allow_pickle=False)
ka,kb=set(a.files),set(b.files)
if ka!=kb: print("keys differ", ka^kb)
def eq(x,y):
    if x.shape!=y.shape or x.dtype!=y.dtype: return False
    if x.dtype.kind=='f': return np.array_equal(x,y,equal_nan=True)
    return np.array_equal(x,y)
diff=[k for k in sorted(ka&kb) if not eq(a[k],b[k])]
print(len(ka&kb),"arrays;", "differ:", diff[:20])
