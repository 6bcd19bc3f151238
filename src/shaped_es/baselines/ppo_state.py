"""PPO state as plain arrays (never SB3's pickled zip) and test episodes of a deterministic SB3 policy.

Checkpoint keys in the run store's ``.npz`` (read with ``allow_pickle=False``)::

    ppo/policy/<name>        current policy + value net tensors (``policy.state_dict()``)
    ppo/best/<name>          the weights that scored the best test reward so far
    ppo/optim/<i>/<name>     Adam moments and step count of parameter ``i``
    ppo/torch_rng            torch's CPU generator state (action sampling, minibatch order)

The optimizer's ``param_groups`` (numbers only) go in the JSON sidecar.
"""

from __future__ import annotations

import numpy as np
import torch

from shaped_es.env_probe import reward as one_reward
from shaped_es.envs.core import runs_serially
from shaped_es.rollout import make_env

POLICY, BEST, OPTIM, RNG = "ppo/policy/", "ppo/best/", "ppo/optim/", "ppo/torch_rng"


def to_arrays(prefix: str, state: dict[str, torch.Tensor]) -> dict[str, np.ndarray]:
    return {prefix + k: v.detach().cpu().numpy().copy() for k, v in state.items()}


def from_arrays(prefix: str, arrays: dict[str, np.ndarray]) -> dict[str, torch.Tensor]:
    return {k[len(prefix):]: torch.from_numpy(np.array(v)) for k, v in arrays.items() if k.startswith(prefix)}


def copy_state(state: dict[str, torch.Tensor]) -> dict[str, torch.Tensor]:
    return {k: v.detach().clone() for k, v in state.items()}


def optimizer_to_arrays(opt: torch.optim.Optimizer) -> tuple[dict[str, np.ndarray], list[dict]]:
    sd = opt.state_dict()
    arrays = {f"{OPTIM}{i}/{k}": torch.as_tensor(v).cpu().numpy().copy()
              for i, st in sd["state"].items() for k, v in st.items()}
    groups = [{k: (list(v) if isinstance(v, tuple) else v) for k, v in g.items()} for g in sd["param_groups"]]
    return arrays, groups


def optimizer_from_arrays(opt: torch.optim.Optimizer, arrays: dict[str, np.ndarray], groups: list[dict]):
    state: dict[int, dict[str, torch.Tensor]] = {}
    for key, v in arrays.items():
        if key.startswith(OPTIM):
            i, name = key[len(OPTIM):].split("/", 1)
            state.setdefault(int(i), {})[name] = torch.from_numpy(np.array(v))
    groups = [{k: (tuple(v) if k == "betas" else v) for k, v in g.items()} for g in groups]
    opt.load_state_dict({"state": state, "param_groups": groups})


def actor_vector(policy) -> np.ndarray:
    """Flat actor parameters (value net excluded), for ``update_norm`` as ES logs it for its mean."""
    parts = [p.detach().reshape(-1) for name, p in policy.named_parameters()
             if not (name.startswith("value_net") or name.startswith("mlp_extractor.value_net"))]
    return torch.cat(parts).cpu().numpy().astype(np.float64)  # (n_actor,)


class DeterministicEpisodes:
    """Runs a deterministic SB3 policy on given episode seeds, all episodes in lock-step (one forward per
    episode and step, so an episode's actions do not depend on the others')."""

    def __init__(self, env_id: str, env_kwargs: dict, max_steps: int | None):
        self.env_id, self.env_kwargs, self.max_steps = env_id, env_kwargs, max_steps
        self.envs: list = []

    def run(self, policy, seeds: np.ndarray) -> tuple[np.ndarray, int]:
        """Returns per-episode returns ``(E,)`` and the env steps taken."""
        seeds = np.asarray(seeds).reshape(-1)  # (E,)
        if not self.envs:
            self.envs.append(make_env(self.env_id, self.env_kwargs))
        if len(seeds) > 1 and runs_serially(self.envs[0]):  # one simulator per process: one at a time
            parts = [self.run(policy, seeds[i:i + 1]) for i in range(len(seeds))]
            return np.concatenate([r for r, _ in parts]), sum(n for _, n in parts)
        while len(self.envs) < len(seeds):
            self.envs.append(make_env(self.env_id, self.env_kwargs))
        envs = self.envs[: len(seeds)]
        obs = np.stack([np.asarray(env.reset(seed=int(s))[0], dtype=np.float32)
                        for env, s in zip(envs, seeds)])  # (E, obs)
        returns = np.zeros(len(seeds))
        alive = np.ones(len(seeds), dtype=bool)
        steps, t = 0, 0
        while alive.any() and (self.max_steps is None or t < self.max_steps):
            for b in np.flatnonzero(alive):
                # one observation per forward, as load_policy(...).predict(obs) runs it: a batched torch
                # matrix product rounds a row differently depending on the batch, and a chaotic episode
                # would then differ from the same policy driving a plain gymnasium loop
                act, _ = policy.predict(obs[b : b + 1], deterministic=True)  # (1, ...) clipped to the bounds
                o, r, term, trunc, _ = envs[b].step(act[0])
                obs[b], returns[b] = o, returns[b] + one_reward(r)
                alive[b] = not (term or trunc)
                steps += 1
            t += 1
        return returns, steps

    def close(self) -> None:
        for env in self.envs:
            env.close()
        self.envs = []
