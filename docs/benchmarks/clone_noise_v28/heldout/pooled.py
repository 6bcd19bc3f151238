"""noise1 vs noise0 over the seeds of several benchmark dirs' analysis.json (python pooled.py DIR1 DIR2 ...)."""
import json, sys
import numpy as np
from analyze import boot_diff, boot_ratio
dirs = sys.argv[1:]
n1, n0 = [], []
for d in dirs:
    a = json.load(open(f'{d}/analysis.json'))
    for s in a['noise1']:
        if a['noise1'][s] and a['noise0'].get(s):
            n1.append(a['noise1'][s]); n0.append(a['noise0'][s])
print(f'pooled over {dirs}: {len(n1)} seeds\n')
print('| variant | seeds | solved | gens censored mean (median) | late test | late train | accepted / judged per run | median wall s |')
print('|---|---|---|---|---|---|---|---|')
for name, rs in (('noise1', n1), ('noise0', n0)):
    g = [r['gens'] for r in rs]
    print(f"| {name} | {len(rs)} | {sum(r['solved'] for r in rs)}/{len(rs)} | {np.mean(g):.1f} ({np.median(g):.1f}) | {np.mean([r['late_test'] for r in rs]):.2f} | "
          f"{np.mean([r['late_train'] for r in rs]):.2f} | {np.mean([r['acc'] for r in rs]):.1f} / {np.mean([r['judged'] for r in rs]):.1f} | {np.median([r['wall'] for r in rs]):.1f} |")
print()
r = boot_ratio([x['gens'] for x in n1], [x['gens'] for x in n0]); print(f'- gens noise1 / noise0: **{r[0]:.2f}x [{r[1]:.2f}, {r[2]:.2f}]**')
for k, nm in (('late_test', 'late test'), ('late_train', 'late train'), ('acc', 'accepted per run'), ('wall', 'wall s per run')):
    r = boot_diff([x[k] for x in n1], [x[k] for x in n0]); print(f'- {nm} noise1 - noise0: **{r[0]:+.2f} [{r[1]:+.2f}, {r[2]:+.2f}]**')
