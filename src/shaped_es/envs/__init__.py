"""Built-in waypoint environments (batched NumPy cores under thin Gymnasium wrappers) and registration."""

from __future__ import annotations


def register_envs() -> None:
    """Register the built-in envs with Gymnasium (idempotent; entry points import lazily)."""
    import gymnasium as gym

    specs = {
        "CarNav-v0": "shaped_es.envs.carnav.env:CarNavEnv",
        "UR5Reach-v0": "shaped_es.envs.ur5.env:UR5ReachEnv",
    }
    for env_id, entry in specs.items():
        if env_id not in gym.registry:
            gym.register(id=env_id, entry_point=entry)
