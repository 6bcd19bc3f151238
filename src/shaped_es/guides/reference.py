"""The reference policy of the paper's Fig. 5 test loss (``shaping.reference_run``): a finished run's best
policy, ES or PPO, as actions in ``[-1, 1]`` -- the scale of M_phi's labels -- for the label-quality metrics."""

from __future__ import annotations

import numpy as np

from shaped_es.config import ConfigError
from shaped_es.policies import MLPSpec


def reference_actions(run_dir: str, spec: MLPSpec):
    """The reference policy's actions in ``[-1, 1]`` for states ``(..., obs)`` (the scale of M_phi's labels);
    one ``ConfigError`` naming ``shaping.reference_run`` if ``run_dir`` holds no run with a checkpoint, or
    one of another observation size (preflight calls it before the run directory is written)."""
    from shaped_es.env_probe import EnvSpecError
    from shaped_es.trained.load import load_policy
    from shaped_es.policies import forward
    from shaped_es.rundir.store import StoreError

    try:
        pol = load_policy(run_dir)
    except (StoreError, EnvSpecError) as exc:  # no run there, no checkpoint yet, its env cannot be made
        raise ConfigError(f"shaping.reference_run must name a finished run of this env: "
                          f"{str(exc).splitlines()[0]}") from None
    if pol.obs_dim != spec.obs_dim:
        raise ConfigError(f"shaping.reference_run {run_dir} has {pol.obs_dim} observations, this env "
                          f"{spec.obs_dim}")
    if pol.theta is not None:  # an ES run: its flat parameters
        theta, rspec, norm = pol.theta[None], pol.spec, pol.obs_norm

        def es(states: np.ndarray) -> np.ndarray:
            lead = states.shape[:-1]
            x = states if norm is None else norm.apply(states)  # a run trained with es.obs_norm
            return forward(rspec, theta, x.reshape(1, -1, spec.obs_dim))[0].reshape(*lead, -1)
        return es
    low, high = pol.action_space.low, pol.action_space.high

    def sb3(states: np.ndarray) -> np.ndarray:  # PPO: its env action mapped back to [-1, 1]
        lead = states.shape[:-1]
        a = np.asarray(pol.predict(states.reshape(-1, spec.obs_dim)), np.float32)
        return (2.0 * (a - low) / (high - low) - 1.0).reshape(*lead, -1)
    return sb3
