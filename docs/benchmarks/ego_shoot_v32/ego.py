"""Egocentric versions of three suite bodies: the same dynamics, waypoints, rewards and thresholds, but the
observation keeps only what the body senses about itself and its goal and drops its world position and heading
(obs[0:4]), as a robot with goal-relative sensing and no odometry sees itself:

    EgoUnicycle-v0  Unicycle-v0's goal in the body frame (2)
    EgoRover-v0     Rover-v0's forward speed, yaw rate and goal in the body frame (4)
    EgoKart-v0      Kart-v0's speed, steering angle and goal in the body frame (4)

Built as the suite bodies are (a batched core whose ``observe`` drops the four numbers), so a run is as fast as the
suite's; the waypoint controllers are the suite bodies' own (they read the core's state). A user would wrap the
Gymnasium env instead (``gym.wrappers.TransformObservation``), which runs the same episodes one at a time.
"""

import gymnasium as gym

from shaped_es.envs.core import limited_entry_point
from shaped_es.envs.planar.kart import KartCore, KartEnv
from shaped_es.envs.planar.rover import RoverCore, RoverEnv
from shaped_es.envs.planar.unicycle import UnicycleCore, UnicycleEnv

DROP = 4  # world position (2), cos and sin of the heading (2)


def _ego(core_cls, env_cls):
    core = type(f"Ego{core_cls.__name__}", (core_cls,), {
        "obs_dim": core_cls.obs_dim - DROP,
        "observe": lambda self, state: core_cls.observe(self, state)[:, DROP:]})
    return type(f"Ego{env_cls.__name__}", (env_cls,), {"core_cls": core})


for _core, _env, _base in ((UnicycleCore, UnicycleEnv, "Unicycle-v0"), (RoverCore, RoverEnv, "Rover-v0"),
                           (KartCore, KartEnv, "Kart-v0")):
    gym.register(f"Ego{_base}", entry_point=limited_entry_point(_ego(_core, _env)),
                 reward_threshold=gym.spec(_base).reward_threshold)
