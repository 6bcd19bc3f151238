"""``UR5Reach-v0``: a UR5 arm following quadratic-Bezier waypoints to a target (paper, Sec. IV, "UR5
Robot arm in ROS Gazebo"): ``BatchCoreEnv`` (``envs/batch_env.py``) over the batched core (``core.py``)
with B = 1.

=================  ======================================================================================
Action             ``Box(-1, 1, (5,))``: normalized torques of shoulder_pan, shoulder_lift, elbow,
                   wrist_1, wrist_2 (x 150, 150, 150, 28, 28 N m); wrist_3 fixed; gravity compensated
Observation        ``Box(-inf, inf, (13,))``: joint angles (5), joint velocities (5), target - end
                   effector (3). No waypoints.
Reward             ``reward_waypoint`` +M/H when the end effector ends a step within 0.1 of the next
                   waypoint (which then advances by one) + ``reward_step`` -0.1 + ``reward_collision``
                   -50 on any contact (the episode then terminates)
Episode            fixed start pose, target sampled in the upper hemisphere, M = H = 100 steps
info               ``position`` (3,) end effector, ``waypoint`` (3,) next Bezier point, ``target`` (3,),
                   ``waypoint_index``, and the three reward terms (step only)
=================  ======================================================================================

Arguments (``gymnasium.make("shaped_es:UR5Reach-v0", preset="paper", reach_radius=0.05, ...)``):

=================  =============  =======================================================================
argument           default        meaning
=================  =============  =======================================================================
``render_mode``    ``None``       ``"rgb_array"``: ``render()`` returns an offscreen MuJoCo frame
``preset``         ``"default"``  ``"default"`` (target on the front half) or ``"paper"`` (whole hemisphere)
``width, height``  ``480, 360``   frame size in pixels (rendering only)
``**overrides``                   any field of :class:`~shaped_es.envs.ur5.config.UR5Config`
=================  =============  =======================================================================

Seeding, ``info`` and the registered entry points (``make_limited``, ``UR5ReachVectorEnv``): see
:class:`~shaped_es.envs.batch_env.BatchCoreEnv`.
"""

from __future__ import annotations

from typing import Any

from shaped_es.envs.batch_env import BatchCoreEnv
from shaped_es.envs.core import limited_entry_point
from shaped_es.envs.ur5.bezier import bezier_waypoints
from shaped_es.envs.ur5.config import make_config
from shaped_es.envs.ur5.core import UR5Core
from shaped_es.envs.vector import vector_entry_point


class UR5ReachEnv(BatchCoreEnv):
    metadata = {"render_modes": ["rgb_array"], "render_fps": 25}
    env_id = "UR5Reach-v0"
    core_cls = UR5Core
    make_config = staticmethod(make_config)

    def __init__(self, render_mode: str | None = None, preset: str = "default", width: int = 480,
                 height: int = 360, **overrides: Any):
        super().__init__(render_mode, preset, **overrides)
        self._size = (width, height)
        self._renderer = None

    @staticmethod
    def fps(config) -> int:
        return int(round(1.0 / config.control_dt))

    def render_frame(self, state):
        if self._renderer is None:
            from shaped_es.envs.ur5.render import UR5Renderer

            self._renderer = UR5Renderer(self.batch_core.model, *self._size)
        cfg, s = self.config, state
        waypoints = bezier_waypoints(s.start, cfg.control_point, s.target, cfg.num_waypoints)[0]  # (H, 3)
        return self._renderer.render(s.qpos[0], s.target[0], waypoints, int(s.index[0]))

    def close(self):
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None


make_limited = limited_entry_point(UR5ReachEnv)  # the registered entry point
UR5ReachVectorEnv = vector_entry_point(UR5ReachEnv)  # the registered vector_entry_point
