"""``Unicycle-v0``: a differential-drive (unicycle) body, forward speed and turn rate, from a random start
pose to a random goal along spatial waypoints (the shared task: ``task.py``; batched core: ``core.py``).

Dynamics: ``heading += turn_rate * a[1]`` (0.5 rad a step at +-1), then ``p += speed * a[0] *
(cos heading, sin heading)`` (0.05 a step at +-1; negative drives backward). The start heading is
uniform, so the goal is often behind: the body has to turn before the line's waypoints pay.

=================  ======================================================================================
Action             ``Box(-1, 1, (2,))``: forward speed, turn rate (+ = counter-clockwise)
Observation        ``Box(-inf, inf, (6,))``: position (2), cos and sin of the heading (2), goal - position
                   in the body frame (2: ahead, left). No waypoints.
Reward             ``reward_progress`` 10 x the step's progress toward the goal / the start-goal distance +
                   ``reward_step`` -0.01
Episode            random start pose and goal 0.5-1.5 apart; terminates within 0.05 of the goal; 100 steps
info               as PointVel-v0: ``position``, ``waypoint`` (every 0.1 on the line, consumed when reached
                   or passed), ``goal``, ``waypoint_index``, ``num_waypoints``, ``is_success``, reward terms
=================  ======================================================================================

Waypoint controller: turn toward the waypoint (``a[1] = angle / turn_rate``, clipped), drive at
``max(cos angle, 0)`` of full speed (no faster than reaches it).
Threshold (``reward_threshold`` 8.5): the controller scores 9.49 (mean of 20 episodes, min 9.08); 8.5 is
the goal reached with a path's step cost well above the controller's, or nearly reached. Vanilla-ES
(defaults) first reaches it at generation 14 and 28 (seeds 0, 1); its generation-0 test reward is about 0.

Labels: M_phi's ``waypoint`` frame (the query "straight to the waypoint", the heading read from the
state) pays on this body and erases the gain on the holonomic points and CarNav-v0. The default runs it
beside the probe's frame as a rival (``shaping.inverse_dynamics.rival_frame``, ``guides/rival.py``): 11.0
generations to the threshold (seeds 0-9 of the sixth session's default; 0.44x of Vanilla-ES over seeds
0-19; before the rival 14.9, Vanilla-ES 24.5). Forcing
``--set shaping.inverse_dynamics.frame=waypoint`` gives 6.8 (``docs/shaped-results.md``, "The waypoint
frame" and "A rival frame inside the run").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from shaped_es.envs.planar.core import PlanarCore, PlanarState
from shaped_es.envs.planar.env import PlanarEnv, config_maker, entry_points
from shaped_es.envs.planar.heading import forward, heading_obs, wrap
from shaped_es.envs.planar.task import PlanarTaskConfig

ENV_ID = "Unicycle-v0"
REWARD_THRESHOLD = 8.5  # the controller's 9.49 (20 episodes) less a margin: see the module docstring


@dataclass(frozen=True)
class UnicycleConfig(PlanarTaskConfig):
    speed: float = 0.05  # forward action +-1 -> +- this displacement per step
    turn_rate: float = 0.5  # turn action +-1 -> +- this heading change per step (rad)

    def validate(self):
        if self.speed <= 0 or self.turn_rate <= 0:
            raise ValueError(f"{ENV_ID}: speed and turn_rate must be positive")
        return super().validate()


PRESETS = {"default": UnicycleConfig()}
make_config = config_maker(ENV_ID, PRESETS)


class UnicycleCore(PlanarCore):
    obs_dim = 6

    def move(self, state: PlanarState, act: np.ndarray):
        cfg = self.config
        heading = wrap(state.heading + cfg.turn_rate * act[:, 1])  # (B,)
        return forward(state.pos, heading, cfg.speed * act[:, 0]), state.vel, heading

    def observe(self, state: PlanarState) -> np.ndarray:
        return heading_obs(state)

    def waypoint_controller(self, state: PlanarState, obs: np.ndarray, info: dict) -> np.ndarray:
        """Turn toward ``info["waypoint"]``, drive at ``max(cos angle, 0)`` of full speed, ``(B, 2)``."""
        cfg = self.config
        d = np.asarray(info["waypoint"]) - np.asarray(info["position"])  # (B, 2)
        angle = wrap(np.arctan2(d[:, 1], d[:, 0]) - state.heading)  # (B,)
        turn = np.clip(angle / cfg.turn_rate, -1.0, 1.0)
        left = wrap(angle - cfg.turn_rate * turn)  # the angle still to turn after this step's turn
        dist = np.linalg.norm(d, axis=1)
        fwd = np.maximum(np.cos(left), 0.0) * np.minimum(1.0, dist / cfg.speed)
        return np.stack([fwd, turn], axis=1).astype(np.float32)


class UnicycleEnv(PlanarEnv):
    env_id = ENV_ID
    core_cls = UnicycleCore
    make_config = staticmethod(make_config)


make_limited, UnicycleVectorEnv = entry_points(UnicycleEnv)  # the registered entry points
