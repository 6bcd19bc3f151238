"""Replay the probe's frame choice from committed label_probe.json files, with the default scale and a per-pair one."""
import glob, json, sys
import numpy as np
import shaped_es.guides.probe_choice as pc
from shaped_es.guides.probe_variants import variant_name

orig_choose = pc.choose

def choose_pair(returns, incumbent, zero, clones=None):
    # the same rule, with the 5% bar on the spread of the two compared candidates' and zero action's returns
    real = pc.clone_beats
    def per_pair(a, b, scale):
        return real(a, b, float(np.ptp(np.concatenate([np.ravel(a), np.ravel(b), np.ravel(zero)]))))
    pc.clone_beats = per_pair
    try:
        return orig_choose(returns, incumbent, zero, clones)
    finally:
        pc.clone_beats = real

def replay(d, choose):
    pc.choose = choose
    try:
        returns = {k: np.array(v) for k, v in d["returns"].items()}
        clones = {k: np.array(v) for k, v in d.get("clones", {}).items()}
        tried = d.get("shoot_tried") or ({str(d["shoot_horizon"]): d["shoot"]} if d.get("shoot") else {})
        sim = {**d.get("clones", {}), **{f"shoot:{h}": v for h, v in tried.items()}}
        ranking = sorted([k for k in sim if len(sim[k])], key=lambda k: -float(np.mean(sim[k])))
        long_tag = "+clip4" if any("+clip4" in k for k in returns) else None
        inc = next(iter(returns))
        return pc.choose_targets(returns, inc, np.array(d["zero_action"]), clones, ranking, long_tag)[0]
    finally:
        pc.choose = orig_choose

same = changed = bad = 0
rows = []
for f in sorted(glob.glob("../**/label_probe.json", recursive=True)):
    d = json.load(open(f))
    if not d.get("clones") or "chunk" not in d:
        continue
    stored = variant_name(d["frame"], d["query_clip"], d.get("chunk"))
    try:
        a, b = replay(d, orig_choose), replay(d, choose_pair)
    except Exception as e:
        bad += 1; continue
    if a != stored:
        bad += 1; continue
    if a == b:
        same += 1
    else:
        changed += 1; rows.append((f, a, b))
print("reproduced and same", same, "changed", changed, "not reproduced", bad)
for r in rows: print(*r)
