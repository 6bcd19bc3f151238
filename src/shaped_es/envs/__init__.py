"""Built-in waypoint environments (batched NumPy cores under thin Gymnasium wrappers) and registration."""

from __future__ import annotations

# id -> module holding ``make_limited`` (the env under a TimeLimit of its config's horizon), the
# ``VectorEnv`` over its batched core (``gymnasium.make_vec``'s ``vector_entry_point``; None: the env has
# no batched core) and the EnvSpec's ``reward_threshold`` (the test return that counts as solved, at the
# default preset; its reason in the env module's docstring; None: none). CarlaNav-v0's module imports
# ``carla`` only when an env is made, so registering it needs nothing and making it without the extra
# says ``pip install -e '.[carla]'`` in one line.
BUILTIN = {
    # 200: the route driven to (nearly) its end; stalling or crashing scores about -25
    "CarNav-v0": ("shaped_es.envs.carnav.env", "CarNavVectorEnv", 200.0),
    # 40: half the Bezier path followed without a collision (the follower scores 90, standing still -4)
    "UR5Reach-v0": ("shaped_es.envs.ur5.env", "UR5ReachVectorEnv", 40.0),
    "CarlaNav-v0": ("shaped_es.envs.carla.env", None, None),
    # the waypoint task suite (benchmark/suite.py): each threshold is its controller's return less a margin
    "PointVel-v0": ("shaped_es.envs.planar.pointvel", "PointVelVectorEnv", 8.5),
    "PointForce-v0": ("shaped_es.envs.planar.pointforce", "PointForceVectorEnv", 8.5),
    "Unicycle-v0": ("shaped_es.envs.planar.unicycle", "UnicycleVectorEnv", 8.5),
    "Rover-v0": ("shaped_es.envs.planar.rover", "RoverVectorEnv", 8.0),
    "Kart-v0": ("shaped_es.envs.planar.kart", "KartVectorEnv", 8.0),
    "ReacherWay-v0": ("shaped_es.envs.reacher", "ReacherWayVectorEnv", -6.5),
    "SwimmerWay-v0": ("shaped_es.envs.swimmer", "SwimmerWayVectorEnv", 30.0),
}


def register_envs() -> None:
    """Register the built-in envs with Gymnasium (idempotent; entry points import lazily).

    The time limit is not a fixed ``max_episode_steps`` in the registry: it depends on the preset and
    overrides (``CarNav-v0``: 250 steps by default, 1000 with ``preset="paper"``), so the entry point
    wraps the env in a ``TimeLimit`` of its own config's ``max_steps`` and ``env.spec.max_episode_steps``
    of every made env holds it (what PPO and other libraries read).
    """
    import gymnasium as gym

    for env_id, (module, vector, threshold) in BUILTIN.items():
        if env_id not in gym.registry:
            gym.register(id=env_id, entry_point=f"{module}:make_limited", reward_threshold=threshold,
                         vector_entry_point=f"{module}:{vector}" if vector else None)
