"""Per-body analysis of a noise1 / noise0 benchmark directory.
usage: python analyze.py BENCH_DIR THRESHOLD BUDGET [--old OLD_BENCH_DIR]"""
import csv, sys, os, json
import numpy as np

def load(run):
    p = os.path.join(run, 'metrics.csv')
    if not os.path.exists(p):
        return None
    return list(csv.DictReader(open(p)))

def f(x):
    try: return float(x)
    except (TypeError, ValueError): return float('nan')

def per_run(rows, T, G):
    if rows is None or len(rows) < G:
        return None
    test = [f(r['test_reward_mean']) for r in rows]
    train = [f(r['train_reward_mean']) for r in rows]
    gens = G + 1
    for r, t in zip(rows, test):
        if t >= T:
            gens = int(r['generation']) + 1; break
    acc = sum(1 for r in rows if r.get('candidate_accepted', '') not in ('', None) and f(r['candidate_accepted']) == 1)
    judged = sum(1 for r in rows if r.get('candidate_accepted', '') not in ('', None))
    tt = [t for t in test if t == t]
    return dict(gens=gens, solved=gens <= G, late_test=float(np.mean(tt[-10:])), late_train=float(np.mean(train[-10:])),
                acc=acc, judged=judged, wall=f(rows[-1]['wall_time_s']))

def boot_ratio(a, b, n=10000, rng=np.random.default_rng(0)):
    a, b = np.asarray(a, float), np.asarray(b, float)
    idx = rng.integers(0, len(a), (n, len(a)))
    r = a[idx].mean(1) / b[idx].mean(1)
    return a.mean() / b.mean(), np.percentile(r, 2.5), np.percentile(r, 97.5)

def boot_diff(a, b, n=10000, rng=np.random.default_rng(1)):
    d = np.asarray(a, float) - np.asarray(b, float)
    idx = rng.integers(0, len(d), (n, len(d)))
    m = d[idx].mean(1)
    return d.mean(), np.percentile(m, 2.5), np.percentile(m, 97.5)

def main():
    d, T, G = sys.argv[1], float(sys.argv[2]), int(sys.argv[3])
    old = sys.argv[sys.argv.index('--old') + 1] if '--old' in sys.argv else None
    import glob, re
    seeds = sorted({int(re.search(r'_s(\d+)$', p).group(1)) for p in glob.glob(f'{d}/runs/noise*_s*')})
    res = {}
    for v in ('noise1', 'noise0'):
        res[v] = {s: per_run(load(f'{d}/runs/{v}_s{s}'), T, G) for s in seeds}
    paired = [s for s in seeds if res['noise1'][s] and res['noise0'][s]]
    out = []
    out.append(f'threshold {T}, budget {G} generations; seeds finished in both variants: {paired} ({len(paired)}/{len(seeds)} seeds with a run folder)')
    out.append('')
    out.append('| variant | seeds | solved | generations to threshold, censored mean (median) | late test reward (mean of seeds) | late train_reward_mean | accepted / judged per run (mean) | median wall s/run |')
    out.append('|---|---|---|---|---|---|---|---|')
    for v in ('noise1', 'noise0'):
        rs = [res[v][s] for s in paired]
        if not rs: continue
        g = [r['gens'] for r in rs]
        out.append(f"| {v} | {len(rs)} | {sum(r['solved'] for r in rs)}/{len(rs)} | {np.mean(g):.1f} ({np.median(g):.1f}) | "
                   f"{np.mean([r['late_test'] for r in rs]):.2f} | {np.mean([r['late_train'] for r in rs]):.2f} | "
                   f"{np.mean([r['acc'] for r in rs]):.1f} / {np.mean([r['judged'] for r in rs]):.1f} | {np.median([r['wall'] for r in rs]):.1f} |")
    if old:
        for v in ('vanilla', 'shaped'):
            rs = [per_run(load(f'{old}/runs/{v}_s{s}'), T, G) for s in range(10)]
            rs = [r for r in rs if r]
            if not rs: continue
            g = [r['gens'] for r in rs]
            out.append(f"| old {v} (earlier code, earlier load) | {len(rs)} | {sum(r['solved'] for r in rs)}/{len(rs)} | {np.mean(g):.1f} ({np.median(g):.1f}) | "
                       f"{np.mean([r['late_test'] for r in rs]):.2f} | {np.mean([r['late_train'] for r in rs]):.2f} | "
                       f"{np.mean([r['acc'] for r in rs]):.1f} / {np.mean([r['judged'] for r in rs]):.1f} | {np.median([r['wall'] for r in rs]):.1f} |")
    if len(paired) >= 2:
        a = {k: [res['noise1'][s][k] for s in paired] for k in ('gens', 'late_test', 'late_train', 'acc', 'wall')}
        b = {k: [res['noise0'][s][k] for s in paired] for k in ('gens', 'late_test', 'late_train', 'acc', 'wall')}
        out.append('')
        out.append('Paired over seeds (bootstrap 10,000 resamples of seeds, percentile 95%):')
        out.append('')
        r = boot_ratio(a['gens'], b['gens'])
        out.append(f'- generations to threshold, noise1 / noise0: **{r[0]:.2f}x [{r[1]:.2f}, {r[2]:.2f}]**')
        for k, name in (('late_test', 'late test reward'), ('late_train', 'late population mean (train_reward_mean)'), ('acc', 'candidates accepted per run'), ('wall', 'wall time per run, s')):
            r = boot_diff(a[k], b[k])
            out.append(f'- {name}, noise1 - noise0: **{r[0]:+.2f} [{r[1]:+.2f}, {r[2]:+.2f}]**')
        out.append('')
        out.append('Per seed (gens to threshold, N = not reached; late test; late train; accepted):')
        out.append('')
        out.append('| seed | ' + ' | '.join(str(s) for s in paired) + ' |')
        out.append('|---|' + '---|' * len(paired))
        for v in ('noise1', 'noise0'):
            out.append(f'| {v} gens | ' + ' | '.join(str(res[v][s]['gens']) if res[v][s]['solved'] else 'N' for s in paired) + ' |')
        for v in ('noise1', 'noise0'):
            out.append(f'| {v} late test | ' + ' | '.join(f"{res[v][s]['late_test']:.2f}" for s in paired) + ' |')
        for v in ('noise1', 'noise0'):
            out.append(f'| {v} late train | ' + ' | '.join(f"{res[v][s]['late_train']:.2f}" for s in paired) + ' |')
        for v in ('noise1', 'noise0'):
            out.append(f'| {v} accepted | ' + ' | '.join(str(res[v][s]['acc']) for s in paired) + ' |')
    if old:
        van = [per_run(load(f'{old}/runs/vanilla_s{s}'), T, G) for s in range(10)]
        van = [r['gens'] for r in van if r]
        if van:
            out.append('')
            out.append('Against the old study\'s Vanilla-ES (unpaired: each side\'s seeds resampled on their own, 10,000 resamples):')
            out.append('')
            rng = np.random.default_rng(2)
            for v in ('noise1', 'noise0'):
                g = np.array([res[v][s]['gens'] for s in paired], float); vv = np.array(van, float)
                bs = [g[rng.integers(0, len(g), len(g))].mean() / vv[rng.integers(0, len(vv), len(vv))].mean() for _ in range(10000)]
                out.append(f'- {v} / Vanilla-ES generations: {g.mean() / vv.mean():.2f}x [{np.percentile(bs, 2.5):.2f}, {np.percentile(bs, 97.5):.2f}]')
    print('\n'.join(out))
    json.dump(res, open(os.path.join(d, 'analysis.json'), 'w'), indent=1, default=float)

if __name__ == "__main__":
    main()
