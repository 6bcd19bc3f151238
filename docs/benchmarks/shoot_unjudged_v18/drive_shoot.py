"""Label-driven returns of the shooting labels per horizon and cost, on the probe's data and episodes."""
import sys, json, numpy as np
from shaped_es.config import build_config
from shaped_es.rollout import policy_spec, probe_env, make_env, to_space
from shaped_es.envs.core import POSITION_KEY, WAYPOINT_KEY
from shaped_es.guides.shaped_setup import mphi_config, waypoint_dim
from shaped_es.guides.label_probe import collect, probe_seeds
from shaped_es.guides.clone_probe import shoot_labels
from shaped_es import seeding

def drive_shoot(cfg, lab, seeds):
    env = make_env(cfg.env, cfg.env_kwargs)
    rets = []
    for s in seeds:
        obs, info = env.reset(seed=int(s))
        pos = np.asarray(info[POSITION_KEY], np.float64); wb = pos.copy(); wp = np.asarray(info[WAYPOINT_KEY], np.float64)
        ret, t = 0.0, 0
        while True:
            err = wp - pos + lab.ahead * (wp - wb)
            a = lab(np.asarray(obs, np.float32).reshape(1, -1), err.reshape(1, -1).astype(np.float32))[0]
            obs, r, term, trunc, info = env.step(to_space(env.action_space, np.clip(a, -1, 1)))
            ret += float(r); t += 1
            if term or trunc or (cfg.rollout.max_steps is not None and t >= cfg.rollout.max_steps):
                break
            pos = np.asarray(info[POSITION_KEY], np.float64)
            nw = np.asarray(info[WAYPOINT_KEY], np.float64)
            if np.any(nw != wp): wb, wp = wp, nw
        rets.append(ret)
    env.close()
    return np.array(rets)

def probe_setup(env_id, seed, inverse_dynamics=None):
    """A shaped run's config at ``seed`` (``inverse_dynamics``: settings over the defaults), its policy spec,
    waypoint dimension, M_phi settings, the label probe's recorded data and its episode seeds."""
    cfg = build_config({"env": env_id, "method": "shaped", "seed": seed,
                        **({"shaping": {"inverse_dynamics": inverse_dynamics}} if inverse_dynamics else {})})
    ep = probe_env(cfg.env, cfg.env_kwargs, reset=True)
    spec, d = policy_spec(cfg, ep), waypoint_dim(cfg, ep)
    data, _ = collect(cfg, spec, seeding.initial_mean(spec, seed))
    return cfg, spec, d, mphi_config(cfg, d), data, probe_seeds(cfg)


def run(env_id, seed, hs=(4, 8, 16), costs=("min", "mean")):
    cfg, spec, d, mc, data, seeds = probe_setup(env_id, seed)
    out = {}
    zero = drive_shoot(cfg, type("Z", (), {"ahead": 0.0, "__call__": lambda self, s, q: np.zeros((1, spec.act_dim), np.float32)})(), seeds)
    out["zero"] = zero.tolist()
    for h in hs:
        lab = shoot_labels(cfg, spec, data, d, mc, h)
        for c in costs:
            lab.cost = c
            out[f"{h}{c}"] = drive_shoot(cfg, lab, seeds).tolist()
    return out

if __name__ == "__main__":
    env = sys.argv[1]; res = {}
    for seed in [int(x) for x in sys.argv[2].split(",")]:
        o = run(env, seed); res[seed] = o
        print(env, f"s{seed}", " ".join(f"{k} {np.mean(v):.2f}" for k, v in o.items()), flush=True)
    json.dump(res, open(f"drive_{env.replace(':','_')}.json", "w"))
