import json,glob,sys,numpy as np
def show(pattern):
    n=k=0
    for f in sorted(glob.glob(pattern, recursive=True)):
        d=json.load(open(f))
        if d.get('shoot_on') is not False: continue
        z=np.mean(d['zero_action']); cl={kk:float(np.mean(v)) for kk,v in d['clones'].items()}
        st={kk:float(np.mean(v)) for kk,v in (d.get('shoot_tried') or {}).items()} or ({str(d['shoot_horizon']):float(np.mean(d['shoot']))} if d['shoot'] else {})
        if not st: continue
        bs=float(np.mean(d["shoot"])); bc=max(cl.values()) if cl else -1e9
        n+=1; keep=bs>bc; k+=keep
        print(f.split('/')[-4] if 'suite' in f else f.split('/')[-3], f.split('/')[-2], 'zero %.1f bestclone %.1f bestshoot %.1f'%(z,bc,bs), 'KEEP' if keep else '')
    print(pattern, 'dropped', n, 'kept by new rule', k)
for p in sys.argv[1:]: show(p)
