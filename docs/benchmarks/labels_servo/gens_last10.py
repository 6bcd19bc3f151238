import csv,sys,glob,numpy as np,os
thr=float(sys.argv[2]); 
for d in sys.argv[1].split(","):
  G=[];L=[];A=[]
  for f in sorted(glob.glob(d+"/metrics.csv")):
    rows=list(csv.DictReader(open(f)));t=np.array([float(r["test_reward_mean"]) for r in rows])
    hit=np.flatnonzero(t>=thr); G.append(hit[0] if hit.size else len(t)+1); L.append(t[-10:].mean())
    A.append(sum(r.get("candidate_accepted") in ("1","1.0") for r in rows))
  print(d, "n",len(G),"gens",G,"mean %.1f"%np.mean(G),"solved",sum(g<=80 for g in G),"last10 %.2f"%np.mean(L),"acc",A)
