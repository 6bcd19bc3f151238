"""noise05 runs (HALF_DIR) against noise1 / noise0 of the same seeds (BODY_DIR/analysis.json), paired:
python half_vs.py BODY_DIR HALF_DIR THRESHOLD BUDGET   (``table`` also serves analyze_half.py)"""
import json, sys
import numpy as np
from analyze import boot_diff, boot_ratio, load, per_run


def table(d, G):
    """The noise1 / noise05 / noise0 table of ``d`` (variant -> per_run rows, paired by seed), then noise05's
    ratios and differences against each."""
    print('| variant | solved | gens censored mean (median) | late test | late train | accepted / run | median wall s |')
    print('|---|---|---|---|---|---|---|')
    for name in ('noise1', 'noise05', 'noise0'):
        rs = d[name]; g = [r['gens'] for r in rs]
        print(f"| {name} | {sum(r['gens'] <= G for r in rs)}/{len(rs)} | {np.mean(g):.1f} ({np.median(g):.1f}) | {np.mean([r['late_test'] for r in rs]):.2f} | "
              f"{np.mean([r['late_train'] for r in rs]):.2f} | {np.mean([r['acc'] for r in rs]):.1f} | {np.median([r['wall'] for r in rs]):.1f} |")
    print()
    for other in ('noise0', 'noise1'):
        r = boot_ratio([x['gens'] for x in d['noise05']], [x['gens'] for x in d[other]])
        print(f'- gens noise05 / {other}: {r[0]:.2f}x [{r[1]:.2f}, {r[2]:.2f}]')
        for k in ('late_test', 'late_train'):
            r = boot_diff([x[k] for x in d['noise05']], [x[k] for x in d[other]])
            print(f'- {k} noise05 - {other}: {r[0]:+.2f} [{r[1]:+.2f}, {r[2]:+.2f}]')


if __name__ == "__main__":
    body, half, T, G = sys.argv[1], sys.argv[2], float(sys.argv[3]), int(sys.argv[4])
    a = json.load(open(f'{body}/analysis.json'))
    h = {s: per_run(load(f'{half}/runs/noise05_s{s}'), T, G) for s in a['noise1']}
    ok = [s for s in a['noise1'] if h[s] and a['noise1'][s] and a['noise0'][s]]
    print(f'{half}: seeds finished {ok} ({len(ok)}); noise05 gens per seed {[h[s]["gens"] for s in ok]}\n')
    table({'noise1': [a['noise1'][s] for s in ok], 'noise05': [h[s] for s in ok], 'noise0': [a['noise0'][s] for s in ok]}, G)
