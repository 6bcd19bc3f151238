"""Offline: per label formulation, label-driven return and simulated candidate (clone) return."""
import sys, time, json
from dataclasses import replace
import numpy as np
sys.path.insert(0, "/work/main/src")
from shaped_es import seeding
from shaped_es.config import build_config
from shaped_es.rollout import policy_spec, probe_env
from shaped_es.guides.shaped_setup import mphi_config, waypoint_dim
from shaped_es.guides import label_probe as lp, probe_rollouts
from shaped_es.guides.clone_probe import clone_rounds
from shaped_es.shaping.inverse_dynamics import InverseDynamics
from shaped_es.shaping.labels import MphiLabels, LabelSource
from shaped_es.envs.core import get_batch_core
import gymnasium as gym
from shaped_es.shaping import frames as F, settings as ST, mphi_inputs as MI, inverse_dynamics as ID
_to, _dim, _q = F.to_frame, F.frame_dim, lp.query
def to_frame(tr, disp, frame):
    if frame.endswith("last"):
        return np.concatenate([_to(tr, disp, frame[:-4] or "world"), F.last_step(tr).astype(disp.dtype)], 1)
    return _to(tr, disp, frame)
def frame_dim(frame, d):
    return _dim(frame[:-4] or "world", d) + d if frame.endswith("last") else _dim(frame, d)
def query(pos, wp, prev, frame, mix=1.0):
    if frame.endswith("last"):
        return np.concatenate([_q(pos, wp, prev, frame[:-4] or "world", mix), (pos - prev).astype(np.float32)], 1)
    return _q(pos, wp, prev, frame, mix)
_tp = MI.target_pairs
def target_pairs(tr, frame, targets="one_step", horizon=8, rng=None):
    if targets != "chunk":
        return _tp(tr, frame, targets, horizon, rng)
    end = MI.episode_end(tr); idx = np.arange(len(tr)); room = end - idx; rows = room > 0
    h = np.minimum(horizon, np.maximum(room, 1))
    disp = MI.to_frame(tr, tr.position[np.minimum(idx + h, end)] - tr.position, frame)
    cs = np.concatenate([np.zeros((1, tr.action.shape[1])), np.cumsum(tr.action.astype(np.float64), 0)])
    a = (cs[idx + h] - cs[idx]) / h[:, None]
    return tr.state[rows], disp[rows], a[rows].astype(np.float32)
MI.target_pairs = ID.target_pairs = target_pairs
ST.TARGETS = ST.TARGETS + ("chunk",)
F.FRAMES = ST.FRAMES = F.FRAMES + ("last", "bothlast")
MI.to_frame = to_frame; ID.frame_dim = frame_dim; probe_rollouts.query = query  # drive (probe_rollouts.py) reads it

class GainL(MphiLabels):
    k = 1.0
    def __call__(self, states, inputs):
        d = inputs.shape[1] // 2 if self.frame == "last" else inputs.shape[1] // 3
        q = inputs.copy(); q[:, :-d] *= self.k
        from shaped_es.shaping.labels import clip_norm
        if self.max_displacement is not None:
            q[:, :-d] = clip_norm(q[:, :-d], self.max_displacement)
        return self.mphi.label(states, q)


env_id = sys.argv[1]; seeds_run = [int(s) for s in sys.argv[2].split(",")]
variants = sys.argv[3].split(",")

class Ctrl(LabelSource):
    records_expert = True
    def inputs(self, tr): return np.asarray(tr.expert, np.float32)
    def __call__(self, s, i): return np.asarray(i, np.float32)

class Gain(MphiLabels):
    k = 1.0
    def __call__(self, states, inputs):
        return super().__call__(states, self.k * inputs)

import os
probe_rollouts.GENERATIONS = int(os.environ.get("GENS", "2"))
out = {}
for seed in seeds_run:
    cfg = build_config({"env": env_id, "method": "shaped", "seed": seed})
    envp = probe_env(cfg.env, cfg.env_kwargs, reset=True)
    spec, pos_dim = policy_spec(cfg, envp), waypoint_dim(cfg, envp)
    base = mphi_config(cfg, pos_dim)
    x0 = spec.init(seeding.derive_seed(cfg.seed, seeding.INIT))
    data, _ = lp.collect(cfg, spec, x0)
    seeds = np.array([seeding.derive_seed(cfg.seed, seeding.SHAPING, lp.PROBE_KEY, 1000 + e) for e in range(10)])
    res = {}
    for v in variants:
        parts = v.split(":")  # frame:targets:horizon:clip:gain:mix
        frame, targets, hz, clip = parts[0], parts[1], int(parts[2]), (None if parts[3] == "none" else float(parts[3]))
        k = float(parts[4]) if len(parts) > 4 else 1.0
        mix = float(parts[5]) if len(parts) > 5 else 1.0
        t0 = time.time()
        m = InverseDynamics(spec.obs_dim, pos_dim, spec.act_dim, replace(base, frame=frame, targets=targets, horizon=hz, hidden=tuple(int(x) for x in os.environ.get("HID", "20,20").split(","))))
        for trs in data:
            m.add(trs); L = m.train(int(os.environ.get("TRAIN", "500")))
        x = m.newest(m.dataset_size)[0][:, spec.obs_dim:]
        step = float(np.linalg.norm(x, axis=1).mean())
        lab = (GainL if frame.endswith('last') else Gain)(m, frame, base.query_scale, mix)
        lab.k = k
        lab.max_displacement = None if clip is None else clip * step
        r, _ = lp.drive(cfg, lab, frame, seeds, mix)
        c, _ = clone_rounds(cfg, spec, x0, [t for g in data for t in g], lab, seeds, 0)
        print("loss", np.mean(L[-50:]), "var", float(m._y.var(0).sum()))
        res[v] = (float(np.mean(r)), float(np.mean(c)))
        print(env_id, seed, v, f"drive {np.mean(r):.2f} clone {np.mean(c):.2f}  ({time.time()-t0:.1f}s)", flush=True)
    out[seed] = res
print(json.dumps(out))
