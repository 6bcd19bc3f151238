"""Load a trained policy from a run directory and use it from Python.

.. code-block:: python

    import gymnasium as gym
    from shaped_es import load_policy

    policy = load_policy("runs/quickstart")          # which="best" (default) or "mean"
    env = policy.make_env()                          # gymnasium.make(the run's env id, **its env_kwargs)
    seeds = policy.evaluation_seeds(15)              # the episodes of shaped-es evaluate --episodes 15
    obs, _ = env.reset(seed=0)
    action = policy.predict(obs)                     # one observation -> one action
    actions = policy.predict(obs_batch)              # (B, obs_dim) -> (B, act_dim), (B,) for Discrete, (B, k) for
                                                     # MultiDiscrete(nvec of k), (B, n) for MultiBinary(n)
    module = policy.to_torch()                       # torch.nn.Module, same actions as predict

Actions are those ``shaped-es evaluate`` feeds the env: ES policies output ``[-1, 1]``, rescaled to a
``Box``'s bounds (an argmax for ``Discrete``, one per sub-action for ``MultiDiscrete``, a sign per bit for
``MultiBinary``: ``shaped_es/actions.py``); PPO runs give SB3's deterministic action (clipped to the
bounds). PPO runs load the same way (``policy.sb3_policy`` is the SB3 ``ActorCriticPolicy``).

A run trained with ``es.obs_norm`` saves the normalizer its policies saw (``policy.obs_norm``,
``policies.ObsNorm``: ``clip((obs - mean) / std, -5, 5)``); ``predict``, ``to_torch``, ``evaluate`` and
``render`` apply it, so a plain Gymnasium loop on raw observations acts as the rollouts did. "best" keeps
the normalizer it was tested with; "mean" takes the run's latest statistics (those its next generation
would see).

``which``: ``"best"`` is the policy with the best test reward so far (what ``evaluate`` and ``render``
use by default; ``policy.generation`` says when it was found); ``"mean"`` is the latest (ES: the search
distribution's mean; PPO: the latest weights). Both come from the run's newest checkpoint
(``policy.checkpoint_generation``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from shaped_es.rundir.store import RunStore, StoreError

WHICH = ("best", "mean")


@dataclass
class Policy:
    """A trained policy of one run; see the module docstring."""

    run_dir: Path
    method: str  # vanilla | guided | cmaes | shaped | ppo
    which: str  # best | mean
    # the policy's own generation, counted as generations done (metrics.csv row ``generation - 1``):
    # "best": when its test episodes made it the best so far (0: the initial policy; None: a checkpoint
    # older than this record whose metrics do not tell); "mean": the checkpoint's
    generation: int | None
    checkpoint_generation: int  # generations done at the checkpoint it is read from
    env_id: str  # the run's Gymnasium id
    env_kwargs: dict  # the run's keyword arguments for gymnasium.make
    max_steps: int | None  # the run's rollout.max_steps: evaluate's cap on episode length (None: the env's)
    observation_space: gym.spaces.Box
    action_space: gym.Space
    theta: np.ndarray | None = None  # ES: flat parameters (num_params,) float32
    spec: Any = None  # ES: policies.MLPSpec
    obs_norm: Any = None  # ES with es.obs_norm: the policies.ObsNorm applied to observations before the MLP
    sb3_policy: Any = field(default=None, repr=False)  # PPO: the SB3 ActorCriticPolicy
    # the env's own observation space where it is not a flat Box (a Dict, ...): the run flattened it, and
    # ``predict`` flattens one such observation the same way (rollout.flat_observations)
    source_observation_space: gym.Space | None = None

    @property
    def obs_dim(self) -> int:
        return int(self.observation_space.shape[0])

    def make_env(self, **kwargs) -> gym.Env:
        """``gymnasium.make`` of the run's env with its ``env_kwargs`` (``kwargs`` override them), capped
        at the run's ``rollout.max_steps`` if it sets one: the episodes ``evaluate`` runs. A ``Dict`` (or other
        non-vector) observation comes flattened, as the run's policy read it (``rollout.flat_observations``)."""
        import shaped_es  # noqa: F401 - registers the built-in envs
        from shaped_es.rollout import flat_observations

        env = flat_observations(gym.make(self.env_id, **{**self.env_kwargs, **kwargs}))  # as the run saw them
        return env if self.max_steps is None else gym.wrappers.TimeLimit(env, self.max_steps)

    def evaluation_seeds(self, episodes: int = 15, seed: int = 12345) -> list[int]:
        """The episode seeds of ``shaped-es evaluate --episodes E --seed S`` (``shaped_es.evaluation_seeds``)."""
        from shaped_es.seeding import evaluation_seeds

        return evaluation_seeds(episodes, seed)

    def predict(self, obs) -> np.ndarray | int:
        """Deterministic action(s) for one observation ``(obs_dim,)`` or a batch ``(B, obs_dim)``; for an env
        with a Dict (or other non-vector) observation, also one observation as that env gives it."""
        if self.source_observation_space is not None and not isinstance(obs, np.ndarray):
            obs = gym.spaces.flatten(self.source_observation_space, obs)  # (obs_dim,) as the run read it
        x = np.asarray(obs, dtype=np.float32)
        single = x.ndim == 1
        if x.shape[-1] != self.obs_dim or x.ndim not in (1, 2):
            raise ValueError(f"predict: expected observations of shape ({self.obs_dim},) or (B, "
                             f"{self.obs_dim}), got {x.shape}")
        x = x.reshape(-1, self.obs_dim)  # (B, obs_dim)
        if self.sb3_policy is not None:
            act, _ = self.sb3_policy.predict(x, deterministic=True)  # (B, ...) clipped to the bounds
            act = np.asarray(act)
            if not isinstance(self.action_space, gym.spaces.Box):  # SB3 gives MultiBinary's bits as float32
                act = act.astype(self.action_space.dtype)
        else:
            from shaped_es.policies import forward
            from shaped_es.rollout import to_space

            if self.obs_norm is not None:
                x = self.obs_norm.apply(x)  # (B, obs_dim) as the rollouts normalize it
            raw = forward(self.spec, self.theta[None], x[None], rowwise=True)[0]  # (B, act) in [-1, 1], row by row
            act = to_space(self.action_space, raw)  # as the rollouts map them
        if single:
            a = act[0]
            return int(a) if isinstance(self.action_space, gym.spaces.Discrete) else a
        return act

    def to_torch(self):
        """A ``torch.nn.Module``: ``obs`` float tensor ``(B, obs_dim)`` -> the actions ``predict`` gives
        (``Box``: float ``(B, act_dim)``; ``Discrete``: int64 ``(B,)``; ``MultiDiscrete``: int64 ``(B, k)``;
        ``MultiBinary``: int8 ``(B, n)``). ES: ``module.net`` is the MLP
        (``nn.Linear`` + ``tanh`` layers, output in ``[-1, 1]``; with ``obs_norm`` its buffers
        ``obs_mean``, ``obs_std`` normalize the input first); PPO: ``module.policy`` is SB3's."""
        if self.sb3_policy is not None:
            return _SB3Actor(self.sb3_policy, self.action_space)
        return _ESActor(self.spec, self.theta, self.action_space, self.obs_norm)


def load_policy(run_dir: str | Path, which: str = "best") -> Policy:
    """The ``which`` ('best' or 'mean') policy of the run in ``run_dir`` (any method, PPO included)."""
    if which not in WHICH:
        raise ValueError(f"which must be one of {WHICH}, got {which!r}")
    import shaped_es  # noqa: F401 - registers the built-in envs
    from shaped_es.rollout import close_env, env_dims, flattened_from, make_env

    store = RunStore(run_dir)
    cfg = store.read_config()
    arrays, meta = store.require_checkpoint()
    env = make_env(cfg.env, cfg.env_kwargs)
    try:
        obs_dim, act_dim = env_dims(env)
        obs_space, act_space, source = env.observation_space, env.action_space, flattened_from(env)
    finally:
        close_env(env)
    common = dict(run_dir=Path(run_dir), method=cfg.method, which=which,
                  generation=policy_generation(store, meta, which), checkpoint_generation=int(meta["generation"]),
                  env_id=cfg.env, env_kwargs=dict(cfg.env_kwargs), max_steps=cfg.rollout.max_steps,
                  observation_space=obs_space, action_space=act_space, source_observation_space=source)
    from shaped_es.methods import METHODS, resolve

    fields = resolve(METHODS[cfg.method].policy_fields)(cfg, arrays, which, run_dir, obs_dim, act_dim)
    return Policy(**common, **fields)


def es_policy_fields(cfg, arrays: dict[str, np.ndarray], which: str, run_dir, obs_dim: int,
                     act_dim: int) -> dict:
    """``Policy``'s fields of an ES checkpoint (``methods.Method.policy_fields``): the MLP, its
    parameters and its observation normalizer (None without ``es.obs_norm``)."""
    from shaped_es.policies import MLPSpec

    spec = MLPSpec(obs_dim, act_dim, tuple(cfg.policy.hidden))
    return {"theta": es_params(arrays, which, spec.num_params, run_dir), "spec": spec,
            "obs_norm": es_obs_norm(arrays, which, obs_dim, run_dir)}


def es_obs_norm(arrays: dict[str, np.ndarray], which: str, obs_dim: int, run_dir):
    """The ``policies.ObsNorm`` the ``which`` policy of an ES checkpoint sees its observations through
    (``es.obs_norm``; None for a run without it): "best", the one it was tested with; "mean", the run's
    latest statistics. Checked: ``obs_dim`` finite entries, positive std (``StoreError`` naming the run)."""
    from shaped_es.policies import ObsNorm, ObsStats

    if "policy/obs_count" not in arrays:
        return None
    try:
        if which == "best":
            norm = ObsNorm(np.asarray(arrays["policy/best_obs_mean"], np.float32),
                           np.asarray(arrays["policy/best_obs_std"], np.float32))
        else:
            norm = ObsStats(float(np.asarray(arrays["policy/obs_count"]).reshape(())),
                            np.asarray(arrays["policy/obs_mean"], np.float64),
                            np.asarray(arrays["policy/obs_m2"], np.float64)).norm()
    except (KeyError, ValueError) as exc:
        raise StoreError(f"checkpoint of {run_dir} has a malformed observation normalizer ({exc})") from None
    if norm.mean.shape != (obs_dim,) or norm.std.shape != (obs_dim,) or not (
            np.isfinite(norm.mean).all() and np.isfinite(norm.std).all() and (norm.std > 0).all()):
        raise StoreError(f"the observation normalizer in the checkpoint of {run_dir} does not fit the env's "
                         f"{obs_dim} observations (or holds inf/NaN)")
    return norm


def es_params(arrays: dict[str, np.ndarray], which: str, num_params: int, run_dir) -> np.ndarray:
    """The ``which`` ('best' or 'mean') policy's parameters ``(n,)`` in an ES checkpoint's ``arrays``,
    checked: present, the config's ``num_params`` of them, finite (``StoreError`` naming the run)."""
    key = f"policy/{which}"
    if key not in arrays:
        raise StoreError(f"checkpoint of {run_dir} has no {which!r} policy")
    theta = np.asarray(arrays[key], dtype=np.float32)
    if theta.shape != (num_params,):
        raise StoreError(f"policy in {run_dir} has {theta.shape} params, the config's policy needs {num_params}")
    if not np.isfinite(theta).all():
        raise StoreError(f"{key} in the checkpoint of {run_dir} holds non-finite values (inf/NaN)")
    return theta


def policy_generation(store: RunStore, meta: dict, which: str) -> int | None:
    """Generations done when the checkpoint's ``which`` policy was made (``Policy.generation``): the
    checkpoint's for "mean"; for "best" its record (``best_generation``), else, for checkpoints older than
    it, the first metrics row whose test reward is the checkpoint's best (None if none is)."""
    if which == "mean":
        return int(meta["generation"])
    g = meta.get("best_generation")
    if type(g) is int:
        return g
    best = meta.get("best_test_reward")
    if best is None:
        return None
    for row in store.read_metrics():
        if row.get("test_reward_mean") not in (None, "") and float(row["test_reward_mean"]) == best:
            return int(row["generation"]) + 1
    return None


def _torch_modules():
    import torch
    from torch import nn

    from shaped_es.actions import is_choice

    class ESActor(nn.Module):
        def __init__(self, spec, theta: np.ndarray, space: gym.Space, obs_norm=None):
            super().__init__()
            self.normalize = obs_norm is not None
            if self.normalize:  # policies.ObsNorm: clip((obs - mean) / std, -OBS_CLIP, OBS_CLIP)
                self.register_buffer("obs_mean", torch.from_numpy(np.array(obs_norm.mean, np.float32)))
                self.register_buffer("obs_std", torch.from_numpy(np.array(obs_norm.std, np.float32)))
            layers: list[nn.Module] = []
            for (i, o), (ws, bs) in zip(spec.layer_shapes, spec.slices()):
                lin = nn.Linear(i, o)
                with torch.no_grad():
                    lin.weight.copy_(torch.from_numpy(theta[ws].reshape(i, o).T.copy()))
                    lin.bias.copy_(torch.from_numpy(theta[bs].copy()))
                layers += [lin, nn.Tanh()]
            self.net = nn.Sequential(*layers)
            self.kind = type(space).__name__ if is_choice(space) else "Box"
            if isinstance(space, gym.spaces.Discrete):
                self.start = int(space.start)
            elif isinstance(space, gym.spaces.MultiDiscrete):  # actions.to_space: an argmax per sub-action
                self.sizes = [int(n) for n in space.nvec]
                self.register_buffer("start", torch.as_tensor(np.asarray(space.start), dtype=torch.int64))
            elif self.kind == "Box":
                low = torch.as_tensor(space.low, dtype=torch.float32)
                high = torch.as_tensor(space.high, dtype=torch.float32)
                self.register_buffer("centre", (high + low) * 0.5)  # rollout.to_space's rescaling
                self.register_buffer("half_width", (high - low) * 0.5)

        def forward(self, obs):
            if self.normalize:
                from shaped_es.policies import OBS_CLIP

                obs = torch.clamp((obs - self.obs_mean) / self.obs_std, -OBS_CLIP, OBS_CLIP)
            a = self.net(obs)
            if self.kind == "Discrete":
                return a.argmax(dim=-1) + self.start
            if self.kind == "MultiDiscrete":
                return torch.stack([p.argmax(dim=-1) for p in torch.split(a, self.sizes, dim=-1)], -1) + self.start
            if self.kind == "MultiBinary":
                return (a > 0).to(torch.int8)
            return self.centre + self.half_width * a

    class SB3Actor(nn.Module):
        def __init__(self, policy, space: gym.Space):
            super().__init__()
            self.policy = policy
            self.box = isinstance(space, gym.spaces.Box)
            self.dtype = None if self.box else getattr(torch, np.dtype(space.dtype).name)  # predict's, as the space's
            if self.box:
                self.register_buffer("low", torch.as_tensor(space.low, dtype=torch.float32))
                self.register_buffer("high", torch.as_tensor(space.high, dtype=torch.float32))

        def forward(self, obs):
            act = self.policy._predict(obs, deterministic=True)  # SB3's deterministic action
            if self.box:
                if getattr(self.policy, "squash_output", False):
                    act = self.low + (act + 1.0) * 0.5 * (self.high - self.low)
                else:
                    act = torch.clamp(act, self.low, self.high)
            return act if self.dtype is None else act.to(self.dtype)

    return ESActor, SB3Actor


def _ESActor(spec, theta, space, obs_norm=None):
    return _torch_modules()[0](spec, theta, space, obs_norm)


def _SB3Actor(policy, space):
    return _torch_modules()[1](policy, space)
