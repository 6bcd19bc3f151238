import json,glob,sys,numpy as np
sys.path.insert(0,"/work/exp/s21/wt/src")
from shaped_es.guides.probe_choice import unjudged, keep_shoot
from shaped_es.guides.label_probe import ProbeResult
for pat in sys.argv[1:]:
    rows={}
    for f in sorted(glob.glob(pat)):
        d=json.load(open(f)); z=np.array(d['zero_action'])
        clones={k:np.array(v) for k,v in d['clones'].items()}; tried={k:np.array(v) for k,v in (d.get('shoot_tried') or {}).items()}
        if not d['shoot']: continue
        new=keep_shoot(np.array(d['shoot']),z,clones,True,True,tried)
        uj=unjudged(z,{**clones,**tried,"shoot":np.array(d['shoot'])})
        ch = (new and uj)
        task=f.split('/')[-4]; seed=f.split('_s')[-1].split('/')[0]
        rows.setdefault(task,[]).append(seed+("*" if ch else ""))
    for t,r in rows.items(): print(t," ".join(r))
