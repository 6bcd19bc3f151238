"""Built-in waypoint environments (batched NumPy cores under thin Gymnasium wrappers) and registration."""

from __future__ import annotations

# id -> module holding ``make_limited`` (the env under a TimeLimit of its config's horizon) and the
# ``VectorEnv`` over its batched core (``gymnasium.make_vec``'s ``vector_entry_point``; None: the env has
# no batched core). CarlaNav-v0's module imports ``carla`` only when an env is made, so registering it
# needs nothing and making it without the extra says ``pip install -e '.[carla]'`` in one line.
BUILTIN = {
    "CarNav-v0": ("shaped_es.envs.carnav.env", "CarNavVectorEnv"),
    "UR5Reach-v0": ("shaped_es.envs.ur5.env", "UR5ReachVectorEnv"),
    "CarlaNav-v0": ("shaped_es.envs.carla.env", None),
}


def register_envs() -> None:
    """Register the built-in envs with Gymnasium (idempotent; entry points import lazily).

    The time limit is not a fixed ``max_episode_steps`` in the registry: it depends on the preset and
    overrides (``CarNav-v0``: 250 steps by default, 1000 with ``preset="paper"``), so the entry point
    wraps the env in a ``TimeLimit`` of its own config's ``max_steps`` and ``env.spec.max_episode_steps``
    of every made env holds it (what PPO and other libraries read).
    """
    import gymnasium as gym

    for env_id, (module, vector) in BUILTIN.items():
        if env_id not in gym.registry:
            gym.register(id=env_id, entry_point=f"{module}:make_limited",
                         vector_entry_point=f"{module}:{vector}" if vector else None)
