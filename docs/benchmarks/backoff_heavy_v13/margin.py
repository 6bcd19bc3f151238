"""How far below the population do never-paying and paying runs' first candidates land? Per run, over its
first streak of losses before any win (at most 8): the highest running median over the first k >= 3 (and
k >= 4) losses of (the population's mean return - the candidate's) / spread ("pop"), and of -gain / spread
(the heavy rule's statistic, "mean"); paying runs listed where "pop" is above 0, never-paying runs all.
Reads ``../test_policy_v11`` and this folder's cheetah runs.

    python docs/benchmarks/backoff_heavy_v13/margin.py
"""
from pathlib import Path

HERE = Path(__file__).resolve().parent
import csv, glob, numpy as np
paths = [p for p in sorted(glob.glob(str(HERE.parent / 'test_policy_v11') + '/*/*/runs/shaped_s*/metrics.csv')) if p.split('/')[-5] in ('suite','suite_10_19','heldout')]
paths += sorted(glob.glob(str(HERE / 'cheetah_30/CheetahWaypoints-v0/runs/shaped_s*/metrics.csv')))
res = []
for p in paths:
    rows = list(csv.DictReader(open(p)))
    name = ('cheetah' if 'cheetah_30' in p else p.split('/')[-4]) + '_' + p.split('_s')[-1].split('/')[0]
    acc = sum(r["candidate_accepted"] in ("1", "1.0") for r in rows)
    pop, mean = [], []
    for r in rows:
        if r['candidate_accepted'] in ('', None): continue
        if r['candidate_accepted'] in ('1','1.0') or len(pop) >= 8: break
        s = float(r["train_reward_max"]) - float(r["train_reward_min"])
        if s <= 0: continue
        c = float(r['mean_return']) + float(r['candidate_gain'])
        pop.append((float(r['train_reward_mean']) - c) / s); mean.append(-float(r['candidate_gain']) / s)
    def mx(x, k):
        return max([float(np.median(x[:i])) for i in range(k, len(x)+1)], default=None)
    res.append((name, acc, mx(pop, 3), mx(pop, 4), mx(mean, 3), mx(mean, 4)))
print('paying: highest running median (pop ref k=3, k=4; mean ref k=3, k=4) over the first streak (<=8 losses)')
for n, a, *m in sorted(res, key=lambda r: -(r[2] or -9)):
    if a > 0 and m[0] is not None and m[0] > 0: print(' ', n, a, [None if x is None else round(x,2) for x in m])
print('never-paying:')
for n, a, *m in res:
    if a == 0: print(' ', n, [None if x is None else round(x,2) for x in m])
