import json,glob,sys,numpy as np

from shaped_es.guides.probe_choice import unjudged, keep_shoot
from shaped_es.guides.probe_variants import variant_name
changed=[];n=0
for pat in sys.argv[1:]:
    for f in sorted(glob.glob(pat, recursive=True)):
        d=json.load(open(f))
        if not d.get('shoot') or not d.get('clones') or not any('clip4' in k for k in d['clones']): continue
        n+=1
        z=np.array(d['zero_action'])
        clones={k:np.array(v) for k,v in d['clones'].items()}; tried={k:np.array(v) for k,v in (d.get('shoot_tried') or {}).items()}
        name=variant_name(d['frame'], d.get('query_clip'), d.get('chunk'))
        passed=[t for t in ("+chunk","+clip4") if t not in name]
        kept={k:v for k,v in clones.items() if not any(t in k for t in passed)}
        old=keep_shoot(np.array(d['shoot']),z,clones,True,True,tried)
        new=keep_shoot(np.array(d['shoot']),z,kept,True,True,tried)
        uo=unjudged(z,{**clones,**tried,"shoot":np.array(d['shoot'])}); un=unjudged(z,{**kept,**tried,"shoot":np.array(d['shoot'])})
        if old!=d['shoot_on']: print("MISMATCH",f,old,d['shoot_on'])
        if (old,uo)!=(new,un): changed.append((f,name,old,new,uo,un))
print(n,"probe files")
for c in changed: print(*c)
