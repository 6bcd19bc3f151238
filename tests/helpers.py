"""Helpers shared by the test folders: ``from helpers import ...`` (``tests/conftest.py`` puts ``tests/`` on
``sys.path``, pytest's default import mode). Runs in this process or as a killable command line, metrics
without their clock columns, and the small loops the strategy tests drive."""

from __future__ import annotations

import io
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from shaped_es.config import RunConfig, build_config
from shaped_es.data import Transitions
from shaped_es.rundir.store import RunStore
from shaped_es.trainer import TIME_COLUMNS, Trainer

SRC = Path(__file__).resolve().parents[1] / "src"

# --- runs ------------------------------------------------------------------------------------------------


CARTPOLE_TINY = {  # a CartPole-v1 ES run that learns in a few seconds (the end-to-end tests' base)
    "env": "CartPole-v1",
    "generations": 6,
    "seed": 3,
    "es": {"pairs": 8, "sigma": 0.1, "lr": 0.05},
    "policy": {"hidden": [8]},
    "rollout": {"episodes": 2, "test_episodes": 3},
    "tensorboard": False,
}

SHAPED_TINY = {  # a default shaped run on UR5Reach-v0 in ~3 s, inline: every data folder a shaped run writes
    "env": "UR5Reach-v0",  # (mphi_data*, trajectories/) and 3 checkpoints (keep_checkpoints' default)
    "method": "shaped",
    "executor": "inline",
    "generations": 3,
    "seed": 1,
    "es": {"pairs": 6},
    "policy": {"hidden": [8]},
    "rollout": {"episodes": 1, "test_episodes": 2, "max_steps": 40},
    "tensorboard": False,
}


# an own env's module, as a user writes it next to their runs (myenvs.py: `--env myenvs:Point-v0`)
POINT_ENV_MODULE = '''
import gymnasium as gym
import numpy as np


class Point(gym.Env):
    """A point pushed towards the origin; 20 steps."""

    observation_space = gym.spaces.Box(-10, 10, (2,), np.float32)
    action_space = gym.spaces.Box(-1, 1, (2,), np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.x = self.np_random.uniform(-1, 1, 2).astype(np.float32)
        return self.x.copy(), {}

    def step(self, action):
        self.x = np.clip(self.x + 0.1 * np.asarray(action, np.float32), -10, 10)
        return self.x.copy(), -float(np.linalg.norm(self.x)), False, False, {}


gym.register("Point-v0", entry_point=Point, max_episode_steps=20)
'''


def new_run(root, cfg: dict | RunConfig) -> tuple[RunConfig, RunStore]:
    """A run directory at ``root`` holding ``cfg`` (a dict is built first); nothing trained yet."""
    cfg = build_config(cfg) if isinstance(cfg, dict) else cfg
    store = RunStore(root)
    store.create(cfg)
    return cfg, store


def train(root, cfg: dict | RunConfig, *, executor=None, ppo=None) -> RunStore:
    """Create the run at ``root`` and train it to the end in this process, quietly; its store. PPO runs
    take ``ppo`` (PPOSettings), the ES methods ``executor`` (None: the one the config names)."""
    cfg, store = new_run(root, cfg)
    if cfg.method == "ppo":
        from shaped_es.baselines.ppo import train_ppo

        train_ppo(cfg, store, progress=False, settings=ppo)
    else:
        Trainer(cfg, store, executor=executor, progress=False).run()
    return store


class Crash(Exception):
    """Raised by :func:`run_until_crash` in place of a generation's step."""


def run_until_crash(monkeypatch, cfg: RunConfig, store: RunStore, crash_at: int) -> None:
    """Train until ``Trainer.step(crash_at)`` raises :class:`Crash`; the real step is back afterwards."""
    step = Trainer.step

    def crashing(self, g):
        if g == crash_at:
            raise Crash
        return step(self, g)

    monkeypatch.setattr(Trainer, "step", crashing)
    with pytest.raises(Crash):
        Trainer(cfg, store, progress=False).run()
    monkeypatch.setattr(Trainer, "step", step)


def strip_time(rows: list[dict]) -> list[dict]:
    """Metrics rows without the columns that measure time (they differ between equal runs)."""
    return [{k: v for k, v in r.items() if k not in TIME_COLUMNS and not k.startswith("time_")} for r in rows]


def popen_cli(*args, **kw) -> subprocess.Popen:
    """``python -m shaped_es.cli.commands *args`` as a child process (so that it can be SIGKILLed), text
    pipes."""
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    return subprocess.Popen([sys.executable, "-m", "shaped_es.cli.commands", *args], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)


def kill_after_rows(proc: subprocess.Popen, run: Path, rows: int, poll: float = 0.01) -> int:
    """SIGKILL ``proc`` once ``run/metrics.csv`` holds ``rows`` rows (or after 120 s); the rows it holds."""
    deadline = time.time() + 120
    while time.time() < deadline:
        m = run / "metrics.csv"
        if m.is_file() and len(m.read_text().splitlines()) >= rows + 1:  # the header + rows
            break
        time.sleep(poll)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    return len((run / "metrics.csv").read_text().splitlines()) - 1


# --- strategies ----------------------------------------------------------------------------------------


def sphere(X):
    """The sphere as a fitness to maximize, summed in float64 whatever the population's dtype."""
    X = np.asarray(X, dtype=np.float64)
    return -np.sum(X * X, axis=1)


def run_generations(es, gens, surrogate=None):
    """``gens`` ask/tell rounds on the shifted sphere; ``surrogate(g, n)`` gives each tell's surrogate.
    Returns the populations (gens, popsize, n) and the means after each tell (gens, n)."""
    Xs, means = [], []
    for g in range(gens):
        X = es.ask()
        Xs.append(X)
        G = None if surrogate is None else surrogate(g, es.num_params)
        es.tell(sphere(X - 0.3), surrogate=G)
        means.append(es.mean.copy())
    return np.stack(Xs), np.stack(means)


def npz_round_trip(state: dict) -> dict:
    """``state`` saved with ``np.savez`` and loaded back without pickle."""
    buf = io.BytesIO()
    np.savez(buf, **state)
    buf.seek(0)
    with np.load(buf, allow_pickle=False) as z:
        return {k: z[k] for k in z.files}


# --- bodies -----------------------------------------------------------------------------------------------


def egocentric_obs(p, heading, w):
    """The waypoint in the car's own frame: all it sees."""
    d = w - p
    c, s = np.cos(heading), np.sin(heading)
    return np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1]])


def _car_step(p, heading, a):
    """Speed ``0.05 (a0 + 1.5) / 2.5`` forward (always moving), turn rate ``0.3 a1``."""
    heading = heading + 0.3 * a[1]
    speed = 0.05 * (a[0] + 1.5) / 2.5
    return p + speed * np.array([np.cos(heading), np.sin(heading)]), heading


def egocentric_car(n_eps=60, T=30, seed=0) -> Transitions:
    """A car's steps (actions held 4 steps, random between) seen only from its own frame (:func:`egocentric_obs`):
    no world heading in its state, as CarNav-v0's and a new user's car-and-trailer (the shooting frame's tests)."""
    rng = np.random.default_rng(seed)
    S, P, W, A, ep, st = [], [], [], [], [], []
    for e in range(n_eps):
        p, heading, w = rng.normal(size=2), rng.uniform(-np.pi, np.pi), rng.normal(size=2) * 2
        for t in range(T):
            if t % 4 == 0:
                a = rng.uniform(-1, 1, size=2)
            S.append(egocentric_obs(p, heading, w)), P.append(p.copy()), W.append(w.copy()), A.append(a.copy())
            ep.append(e), st.append(t)
            p, heading = _car_step(p, heading, a)
    f32 = lambda x: np.asarray(x, np.float32)  # noqa: E731
    return Transitions(0, 0, np.array(ep, np.int32), np.array(st, np.int32), f32(S), f32(P), f32(W), f32(A),
                       np.zeros(len(st), np.float32))


# a weakly actuated 2-D point mass (tests/shaping/test_mphi_step_change.py, tests/guides/test_probe_step_change.py)
DT, GAIN = 0.05, 0.075  # a weakly actuated point mass: a step is mostly the velocity it already has


def point_mass(seed: int, episodes: int = 16, steps: int = 100, gain: float | None = None):
    """A 2-D point mass, ``v += GAIN a`` (or ``gain``), ``p += DT v``, random actions; state ``(p, v)``, waypoint the origin."""
    rng = np.random.default_rng(seed)
    rows = {k: [] for k in ("episode", "step", "state", "position", "waypoint", "action")}
    for e in range(episodes):
        p, v = rng.uniform(-1, 1, 2), rng.uniform(-0.5, 0.5, 2)
        for t in range(steps):
            a = rng.uniform(-1, 1, 2)
            for k, x in (("episode", e), ("step", t), ("state", np.r_[p, v]), ("position", p.copy()),
                         ("waypoint", np.zeros(2)), ("action", a)):
                rows[k].append(x)
            v = np.clip(v + (GAIN if gain is None else gain) * a, -1, 1)
            p = p + DT * v
    f = lambda k, dt: np.asarray(rows[k], dt)  # noqa: E731
    n = len(rows["episode"])
    return Transitions(0, 0, f("episode", np.int32), f("step", np.int32), f("state", np.float32),
                       f("position", np.float32), f("waypoint", np.float32), f("action", np.float32),
                       np.zeros(n, np.float32))
