"""Every accepted jump of the runs under the given folders: its generation, the candidate's and the mean's return, the
population's best and mean, q = (candidate - mean) / (best member - mean) (the share of the gap to the best member
the jump closed). python jumps.py DIR..."""
import csv, sys, glob, os, json
import numpy as np
rows=[]
for root in sys.argv[1:]:
    for f in sorted(glob.glob(os.path.join(root, '**/metrics.csv'), recursive=True)):
        with open(f) as fh:
            r = list(csv.DictReader(fh))
        if not r or 'candidate_accepted' not in r[0]: continue
        for i, x in enumerate(r):
            if x.get('candidate_accepted') not in ('1', '1.0'): continue
            c, m = float(x['candidate_return']), float(x['mean_return'])
            mx, mn = float(x['train_reward_max']), float(x['train_reward_min'])
            mean = float(x['train_reward_mean'])
            q = (c - m) / max(mx - m, 1e-9)
            rows.append(dict(run=f.replace('/metrics.csv',''), g=int(x['generation']), c=c, m=m, mx=mx, mn=mn, pm=mean, q=q,
                             rival=x.get('candidate_rival',''), below=c < mx))
for x in rows:
    print(f"{x['run'][-60:]:60s} g={x['g']:3d} cand={x['c']:9.2f} mean={x['m']:9.2f} popmax={x['mx']:9.2f} popmean={x['pm']:9.2f} q={x['q']:6.2f} rival={x['rival']}")
