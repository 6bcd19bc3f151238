"""Closed-loop label probe: train M_phi on babbling + near-initial population data, then drive the env with
its labels (a_t = M_phi(s_t, query_t)) and report returns vs controller / zero-ish policy."""
import sys, time, json
import numpy as np
import gymnasium as gym
import shaped_es.envs  # noqa  registers
from shaped_es.envs.core import get_batch_core, POSITION_KEY, WAYPOINT_KEY
from shaped_es.policies import MLPSpec
from shaped_es.rollout import RolloutTask, run_task
from shaped_es.shaping.inverse_dynamics import InverseDynamics
from shaped_es.shaping.settings import InverseDynamicsConfig


def collect(env_id, spec, gens=20, babble=16, pop=64, sigma=0.05, seed=0):
    rng = np.random.default_rng(seed)
    mu = spec.init(seed)
    trs = []
    for g in range(gens):
        P = np.concatenate([mu + sigma * rng.standard_normal((pop, spec.num_params)),
                            rng.standard_normal((babble, spec.num_params))]).astype(np.float32)
        m = P.shape[0]
        seeds = rng.integers(0, 2**31, size=(m, 2))
        res = run_task(RolloutTask(env_id, {}, spec, P, np.arange(m), seeds, generation=g, record=True))
        trs.append(res.transitions)
    return trs


def rot(v, ang):
    c, s = np.cos(ang), np.sin(ang)
    return np.stack([c * v[:, 0] + s * v[:, 1], -s * v[:, 0] + c * v[:, 1]], 1)


def closed_loop(env_id, label_fn, episodes=20, seed=12345):
    env = gym.make(env_id)
    core = get_batch_core(env)
    seeds = np.arange(seed, seed + episodes)
    state, obs, info = core.reset(seeds)
    B = episodes
    ret = np.zeros(B); alive = np.ones(B, bool)
    prev = None
    for t in range(core.max_steps):
        pos, wp = info[POSITION_KEY].astype(np.float64), info[WAYPOINT_KEY].astype(np.float64)
        if prev is None:
            prev = pos.copy()
        a = np.clip(label_fn(state, obs, info, pos, wp, prev, core), -1, 1).astype(np.float32)
        prev = pos.copy()
        state, obs, r, term, trunc, info = core.step(state, a)
        ret += np.where(alive, r, 0); alive &= ~(term | trunc)
        if not alive.any():
            break
    return ret.mean(), np.median(ret)


def make_query(frame, mode, gain=1.0, clip=None):
    def q(obs, pos, wp, prev):
        d = (wp - pos)
        v = pos - prev
        if mode == "raw":
            u = d
        elif mode == "gain":
            u = d * gain
        if clip is not None:
            n = np.linalg.norm(u, axis=1, keepdims=True)
            u = u * np.minimum(1, clip / np.maximum(n, 1e-12))
        if frame == "world":
            out = u
        elif frame == "both":
            ang = np.arctan2(v[:, 1], v[:, 0])
            ang = np.where(np.linalg.norm(v, axis=1) > 0, ang, 0.0)
            out = np.concatenate([u, rot(u, ang)], 1)
        return out.astype(np.float32)
    return q



def train_mphi(spec, data, pos_dim, **kw):
    cfg = InverseDynamicsConfig(**kw)
    m = InverseDynamics(spec.obs_dim, pos_dim, spec.act_dim, cfg)
    for trs in data:
        m.add(trs)
        m.train()
    return m


VARIANTS = {
    "one_world": dict(frame="world"),
    "one_both": dict(frame="both"),
    "match_world": dict(frame="world", targets="matched"),
    "match_both": dict(frame="both", targets="matched"),
    "hind_world": dict(frame="world", targets="hindsight"),
}

if __name__ == "__main__":
    env_id = sys.argv[1]
    names = sys.argv[2].split(",") if len(sys.argv) > 2 else list(VARIANTS)
    env = gym.make(env_id)
    spec = MLPSpec(env.observation_space.shape[0], env.action_space.shape[0])
    t0 = time.time()
    data = collect(env_id, spec)
    pos_dim = data[0][0].position.shape[1]
    steps = np.concatenate([np.linalg.norm(np.diff(t.position, axis=0), axis=1) for t in data[0]])
    ms = float(np.mean(steps))
    print(env_id, "collect %.1fs mean step %.4f" % (time.time() - t0, ms))
    print("controller", closed_loop(env_id, lambda st, o, i, p, w, pr, c: c.waypoint_controller(st, o, i)))
    print("zero", closed_loop(env_id, lambda st, o, i, p, w, pr, c: np.zeros((o.shape[0], spec.act_dim))))
    for name in names:
        kw = VARIANTS[name]
        t0 = time.time()
        m = train_mphi(spec, data, pos_dim, **kw)
        for qc in (None, 1.0, 2.0):
            q = make_query(kw["frame"], "raw", clip=None if qc is None else qc * ms)
            r = closed_loop(env_id, lambda st, o, i, p, w, pr, c: m.label(o, q(o, p, w, pr)))
            print(f"{name:12s} qclip={qc} ret mean/med {r[0]:8.3f} {r[1]:8.3f}  ({time.time()-t0:.0f}s)", flush=True)


from shaped_es.shaping.cloning import CloningConfig, clone_sampled
from shaped_es.shaping.member_rows import MemberRows
from shaped_es.shaping.inverse_dynamics import query_displacement


def evaluate(env_id, spec, theta, episodes=20, seed=777, record=False):
    seeds = np.arange(seed, seed + episodes).reshape(1, -1)
    res = run_task(RolloutTask(env_id, {}, spec, theta[None].astype(np.float32), np.arange(1), seeds, record=record))
    return res.returns.mean(), (res.transitions[0] if record else None)


def dagger(env_id, spec, m, frame, mix=1.0, iters=15, steps=200, lr=3e-3, batch=256, history=3, qclip=None, label=None, expert=False):
    theta = spec.init(0).astype(np.float32)
    hist = []
    out = []
    label = label or (lambda s, q: m.label(s, q))
    for it in range(iters):
        # states: the current clone's own rollouts (8 episodes) + population-ish noise members
        rng = np.random.default_rng(it)
        P = (theta + 0.05 * rng.standard_normal((16, spec.num_params))).astype(np.float32)
        res = run_task(RolloutTask(env_id, {}, spec, P, np.arange(16), rng.integers(0, 2**31, (16, 2)), record=True, expert=expert))
        trs = res.transitions
        s = np.concatenate([t.state for t in trs])
        q = np.concatenate([t.expert if expert else query_displacement(t, frame, 'raw', mix) for t in trs])
        if qclip is not None:
            n = np.linalg.norm(q, axis=1, keepdims=True); q = q * np.minimum(1, qclip / np.maximum(n, 1e-12))
        hist.append((s, q)); hist = hist[-history:]
        rows = MemberRows.from_lists([np.concatenate([h[0] for h in hist])], [np.concatenate([h[1] for h in hist])])
        r = clone_sampled(spec, theta[None], rows, label, CloningConfig(steps=steps, lr=lr, batch_size=batch, optimizer="adam"), np.array([it]))
        theta = r.theta_star[0].astype(np.float32)
        ret, _ = evaluate(env_id, spec, theta)
        out.append((round(float(ret), 2), round(float(r.loss_after[0]), 3)))
    return out
