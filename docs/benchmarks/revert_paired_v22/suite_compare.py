"""Per task: a suite arm's shaped runs against the default's runs of the same seeds (the latest of
../probe_clip_long_v16/suite, ../shoot_keep_best_v17/KB, ../shoot_unjudged_v18/suite, ../shoot_unjudged_all_v19/suite,
../probe_horizon32_v20/suite: the README table's numbers, exactly): generations to the threshold (censored mean: an
unsolved run counts budget + 1) with a bootstrap interval of the ratio of means, seeds solved, late test reward (last
10 generations), candidates accepted, jumps undone, and per seed (seed, new, default) generations. Prints JSON.

    python suite_compare.py ARM_DIR [ARM_DIR...]      (PYTHONPATH=src for the suite's tasks and thresholds)"""
import csv, sys, json, glob
from pathlib import Path
import numpy as np
from shaped_es.benchmark.suite import SUITES
from shaped_es.envs.thresholds import threshold_of
B = Path(__file__).resolve().parent.parent
OLD = [B/'probe_clip_long_v16/suite', B/'shoot_keep_best_v17/KB', B/'shoot_unjudged_v18/suite', B/'shoot_unjudged_all_v19/suite', B/'probe_horizon32_v20/suite']
def run(d, thr, budget):
    f = d/'metrics.csv'
    if not f.exists(): return None
    r = list(csv.DictReader(open(f)))
    if len(r) < budget: return None
    t = np.array([float(x['test_reward_mean']) for x in r])
    hit = np.flatnonzero(t >= thr)
    acc = sum(x.get('candidate_accepted') == '1' for x in r)
    rev = sum(x.get('jump_reverted') == '1' for x in r)
    return dict(g=int(hit[0]) + 1 if hit.size else budget + 1, late=float(t[-10:].mean()), acc=acc, rev=rev,
                wall=float(r[-1]['wall_time_s']))
def boot(a, b, n=4000, rng=np.random.default_rng(0)):
    a, b = np.asarray(a, float), np.asarray(b, float); i = rng.integers(0, len(a), (n, len(a)))
    r = a[i].mean(1) / b[i].mean(1); return [round(float(np.percentile(r, 2.5)), 2), round(float(np.percentile(r, 97.5)), 2)]
def main(new_dirs: list[Path]) -> dict:
    out = {}
    for name, task in SUITES['waypoints'].items() if isinstance(SUITES['waypoints'], dict) else [(t.env, t) for t in SUITES['waypoints']]:
        thr = threshold_of(task.env)[0]; G = task.generations
        rows = []
        for s in range(10):
            new = next((run(d/task.env/'runs'/f'shaped_s{s}', thr, G) for d in new_dirs if (d/task.env/'runs'/f'shaped_s{s}').exists()), None)
            old = None
            for d in OLD:
                o = run(d/task.env/'runs'/f'shaped_s{s}', thr, G)
                if o: old = o
            rows.append((s, new, old))
        pair = [(n, o) for s, n, o in rows if n and o]
        if not pair: continue
        gn, go = [n['g'] for n, o in pair], [o['g'] for n, o in pair]
        out[task.env] = dict(seeds=len(pair), new=round(np.mean(gn), 2), old=round(np.mean(go), 2), ratio=round(np.mean(gn)/np.mean(go), 2), ci=boot(gn, go),
            solved_new=sum(g <= G for g in gn), solved_old=sum(g <= G for g in go),
            late_new=round(np.mean([n['late'] for n, o in pair]), 3), late_old=round(np.mean([o['late'] for n, o in pair]), 3),
            acc_new=sum(n['acc'] for n, o in pair), acc_old=sum(o['acc'] for n, o in pair), reverted=sum(n['rev'] for n, o in pair),
            wall_ratio_median=round(float(np.median([n['wall']/o['wall'] for n, o in pair])), 2),
            per_seed=[(s, n['g'] if n else None, o['g'] if o else None) for s, n, o in rows])
    return out


if __name__ == "__main__":
    json.dump(main([Path(p) for p in sys.argv[1:]]), sys.stdout, indent=1)
