"""gravarm noise=0.5 (gravarm_noise05/, gravarm_noise05_s10_19/) against noise1 / noise0 of the same seeds
(gravarm/, gravarm_s10_19/), paired by seed; prints seeds 0-9, seeds 10-19 and the pool of what is finished."""
import json, os
from analyze import load, per_run
from half_vs import table as half_table
sets = [('0-9', 'gravarm_noise05', 'gravarm', range(10)), ('10-19', 'gravarm_noise05_s10_19', 'gravarm_s10_19', range(10, 20))]
pool = {'noise1': [], 'noise05': [], 'noise0': []}
def table(title, d):
    print(f'### {title} ({len(d["noise05"])} seeds)\n')
    half_table(d, 40)
    print()
for title, dh, db, seeds in sets:
    if not os.path.exists(f'{db}/analysis.json'): continue
    a = json.load(open(f'{db}/analysis.json'))
    ok = [s for s in seeds if per_run(load(f'{dh}/runs/noise05_s{s}'), -80, 40) and a['noise1'].get(str(s)) and a['noise0'].get(str(s))]
    if not ok: continue
    d = {'noise05': [per_run(load(f'{dh}/runs/noise05_s{s}'), -80, 40) for s in ok],
         'noise1': [a['noise1'][str(s)] for s in ok], 'noise0': [a['noise0'][str(s)] for s in ok]}
    print('seeds', ok, ' noise05 gens per seed:', [r['gens'] for r in d['noise05']], '\n')
    table('seeds ' + title, d)
    for k in pool: pool[k] += d[k]
table('pooled', pool)
