"""Per folder: how many accepted jumps were below the population's best member (q < 1, 0.5, 0.3, 0.25; q as in
jumps.py), in all and in generations 0-10. python jumpstat.py DIR..."""
import csv, sys, glob, os, collections
import numpy as np
def jumps(root):
    out=[]
    for f in sorted(glob.glob(os.path.join(root, '**/metrics.csv'), recursive=True)):
        with open(f) as fh:
            r = list(csv.DictReader(fh))
        if not r or 'candidate_accepted' not in r[0]: continue
        for x in r:
            if x.get('candidate_accepted') not in ('1', '1.0'): continue
            c, m = float(x['candidate_return']), float(x['mean_return'])
            mx, mn = float(x['train_reward_max']), float(x['train_reward_min'])
            q = (c - m) / (mx - m) if mx > m else 9.0
            out.append((f, int(x['generation']), q, c, m, mx, mn))
    return out
for root in sys.argv[1:]:
    js = jumps(root)
    by = collections.Counter()
    for f, g, q, *_ in js:
        early = g <= 10
        by['all'] += 1
        by['early'] += early
        for t in (1.0, 0.5, 0.3, 0.25):
            if q < t: by[f'q<{t}'] += 1; by[f'early q<{t}'] += early
    print(root, dict(by))
