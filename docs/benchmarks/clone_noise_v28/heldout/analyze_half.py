"""gravarm noise=0.5 (gravarm_noise05/, gravarm_noise05_s10_19/) against noise1 / noise0 of the same seeds
(gravarm/, gravarm_s10_19/), paired by seed; prints seeds 0-9, seeds 10-19 and the pool of what is finished."""
import json, sys, os
sys.argv = ['x']
exec(open('analyze.py').read().split('def main')[0])
sets = [('0-9', 'gravarm_noise05', 'gravarm', range(10)), ('10-19', 'gravarm_noise05_s10_19', 'gravarm_s10_19', range(10, 20))]
pool = {'noise1': [], 'noise05': [], 'noise0': []}
def table(title, d):
    print(f'### {title} ({len(d["noise05"])} seeds)\n')
    print('| variant | solved | gens censored mean (median) | late test | late train | accepted / run | median wall s |')
    print('|---|---|---|---|---|---|---|')
    for name in ('noise1', 'noise05', 'noise0'):
        rs = d[name]; g = [r['gens'] for r in rs]
        print(f"| {name} | {sum(r['gens'] <= 40 for r in rs)}/{len(rs)} | {np.mean(g):.1f} ({np.median(g):.1f}) | {np.mean([r['late_test'] for r in rs]):.2f} | "
              f"{np.mean([r['late_train'] for r in rs]):.2f} | {np.mean([r['acc'] for r in rs]):.1f} | {np.median([r['wall'] for r in rs]):.1f} |")
    print()
    for other in ('noise0', 'noise1'):
        r = boot_ratio([x['gens'] for x in d['noise05']], [x['gens'] for x in d[other]])
        print(f'- gens noise05 / {other}: {r[0]:.2f}x [{r[1]:.2f}, {r[2]:.2f}]')
        for k in ('late_test', 'late_train'):
            r = boot_diff([x[k] for x in d['noise05']], [x[k] for x in d[other]])
            print(f'- {k} noise05 - {other}: {r[0]:+.2f} [{r[1]:+.2f}, {r[2]:+.2f}]')
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
