"""Controllability of the shooting model per horizon: how much the held action moves the predicted end position."""
import sys, json, numpy as np
from shaped_es.guides.clone_probe import shoot_labels
from drive_shoot import probe_setup

def stats(env_id, seed, hs=(4, 8, 16)):
    cfg, spec, d, mc, data, _ = probe_setup(env_id, seed)
    trs = [t for g in data for t in g]
    S = np.concatenate([t.state for t in trs]); P = np.concatenate([t.position for t in trs]); W = np.concatenate([t.waypoint for t in trs])
    rng = np.random.default_rng(0); idx = rng.choice(len(S), min(256, len(S)), replace=False)
    s = S[idx]; dist = np.median(np.linalg.norm(W[idx]-P[idx], axis=1))
    out = {"dist": float(dist)}
    for h in hs:
        lab = shoot_labels(cfg, spec, data, d, mc, h)
        m, A = lab.model, lab.candidates
        K, n = len(A), len(s)
        f = m.predict(np.repeat(s, K, 0), np.tile(A, (n, 1))).reshape(n, K, h, d)  # (n,K,h,d)
        end = f[:, :, -1, :]  # (n,K,d)
        c = end - end.mean(1, keepdims=True)
        cov = np.einsum("nkd,nke->nde", c, c) / K
        ev = np.sqrt(np.clip(np.linalg.eigvalsh(cov), 0, None))  # (n,d) ascending
        drift = np.linalg.norm(end.mean(1), axis=1)  # mean end displacement (motion regardless of action)
        # per world axis spread
        ax = np.sqrt(np.einsum("nkd,nkd->nd", c, c) / K)
        out[h] = dict(smin=float(np.median(ev[:, 0])), smax=float(np.median(ev[:, -1])),
                      ratio=float(np.median(ev[:, 0] / np.maximum(ev[:, -1], 1e-12))),
                      drift=float(np.median(drift)), axis=[float(v) for v in np.median(ax, 0)])
    return out

if __name__ == "__main__":
    env = sys.argv[1]
    for seed in [int(x) for x in sys.argv[2].split(",")]:
        o = stats(env, seed)
        line = f"{env} s{seed} dist {o['dist']:.3f} | " + " | ".join(
            f"h{h}: smin {o[h]['smin']:.3f} smax {o[h]['smax']:.3f} r {o[h]['ratio']:.2f} drift {o[h]['drift']:.3f}" for h in (4, 8, 16))
        print(line, flush=True)
