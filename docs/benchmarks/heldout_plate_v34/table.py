import json, csv, numpy as np
thr=37.3
print("seed | frame | clip | step_change | shoot horizon (kept) | shoot_frame | probe best cand | gen0 won | gen to thr (1-based) | late mean(last10) | accepted/judged")
for s in range(10):
    d=json.load(open(f'runs/shaped_s{s}/label_probe.json'))
    rows=list(csv.DictReader(open(f'runs/shaped_s{s}/metrics.csv')))
    tr=[float(r['test_reward_mean']) for r in rows if r.get('test_reward_mean') not in (None,'')]
    g=[int(r['generation']) for r in rows if r.get('test_reward_mean') not in (None,'') and float(r['test_reward_mean'])>=thr]
    late=np.mean(tr[-10:])
    acc=sum(int(float(r['candidate_accepted'])) for r in rows if r.get('candidate_accepted') not in (None,''))
    print(s, d['frame'], d['query_clip'], d['step_change'], d['shoot_horizon'], d['shoot_on'], d['shoot_frame'], d['candidate'], rows[0].get('candidate_accepted'), (g[0]+1) if g else '-', round(late,2), acc)
for s in range(10):
    rows=list(csv.DictReader(open(f'runs/vanilla_s{s}/metrics.csv')))
    tr=[float(r['test_reward_mean']) for r in rows if r.get('test_reward_mean') not in (None,'')]
    print('vanilla',s,round(np.mean(tr[-10:]),2), round(max(tr),2))
