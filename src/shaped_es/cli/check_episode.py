"""check-env's episodes: one episode of random actions, or of a controller's, recorded as check-env reads it
(observations, rewards, infos) or stopped at its first problem as one line (:func:`_episode`), and whether two
such records are the same episode (:func:`_same`; the seeding check)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np

from shaped_es.actions import action_problem, action_text
from shaped_es.env_probe import BadOutput
from shaped_es.env_probe import reward as one_reward
from shaped_es.cli.check_text import _line


def _episode(env: gym.Env, seed: int, max_steps: int, act=None) -> dict:
    """One episode of random actions (the action space seeded with ``seed``), or of ``act(obs, info)``'s; what
    came back, or the first problem as ``error``."""
    rec = {"obs": [], "rewards": [], "infos": [], "error": None}
    try:
        obs, info = env.reset(seed=seed)
        env.action_space.seed(seed)
        shape = np.shape(obs)
        declared = getattr(env.observation_space, "shape", None)
        if declared is not None and shape != tuple(declared):  # the rollouts refuse it at generation 0 (a new
            #                        user's arm declared 26 floats and returned 23: check-env said ok, train failed)
            rec["error"] = (f"reset (seed {seed}): an observation of shape {shape}, its observation space says "
                            f"{tuple(declared)}")
            return rec
        for t in range(max_steps + 1):
            o = np.asarray(obs, dtype=np.float64)
            if o.shape != shape:
                rec["error"] = f"step {t}: observation shape {o.shape}, reset gave {shape}"
                break
            if not np.isfinite(o).all():
                rec["error"] = f"step {t} (seed {seed}): non-finite observation"
                break
            rec["obs"].append(o)
            rec["infos"].append(info)
            if t == max_steps:
                break
            if act is None:
                a = env.action_space.sample()
            else:
                try:
                    a = act(obs, info)
                except Exception as exc:  # noqa: BLE001 - the controller's own error, as one line
                    rec["error"] = f"it raised {type(exc).__name__}: {_line(str(exc))} (seed {seed}, step {t})"
                    break
                problem = action_problem(env.action_space, a)
                if problem:  # the rollouts refuse it too (a gear out of range would become another option's label)
                    rec["error"] = (f"it returned {action_text(a)}, not an action of {env.action_space} "
                                    f"({problem}; seed {seed}, step {t})")
                    break
                a = np.asarray(a, env.action_space.dtype)
            obs, reward, terminated, truncated, info = env.step(a)
            try:  # the rollouts' own rule: a real number or an array of one
                r = one_reward(reward)
            except BadOutput:
                r = None
            if r is None or not np.isfinite(r):
                rec["error"] = f"step {t + 1} (seed {seed}): reward {reward!r} is not a finite number"
                break
            rec["rewards"].append(r)
            if terminated or truncated:
                rec["obs"].append(np.asarray(obs, dtype=np.float64))
                rec["infos"].append(info)
                break
    except Exception as exc:  # noqa: BLE001 - the env raised: reported as one line
        rec["error"] = f"the env raised {type(exc).__name__}: {_line(str(exc))} (seed {seed})"
    return rec


def _same(a: dict, b: dict) -> bool:
    return (len(a["obs"]) == len(b["obs"]) and all(np.array_equal(x, y) for x, y in zip(a["obs"], b["obs"]))
            and a["rewards"] == b["rewards"])
