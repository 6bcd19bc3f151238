"""``CarNav-v0``: waypoint navigation in a procedurally generated town (the paper's CARLA Town07 task,
Sec. IV): ``BatchCoreEnv`` (``envs/batch_env.py``) over the batched core (``core.py``) with B = 1.

A car starts at a random point of the road network and must drive to a random destination along the
route of a global planner (A* on the road graph; waypoints every 1.5 m, right lane, rounded turns).

=================  ======================================================================================
Action             ``Box(-1, 1, (2,))``: steer (+1 = full left, 35 deg), throttle (+1 = 3 m/s^2; negative
                   brakes, -1 = 8 m/s^2); above 25 km/h the brake is applied automatically
Observation        ``Box(-1, 1, (38,))``, table below. No waypoint coordinates.
Reward             ``reward_waypoint`` +M/H for each global waypoint passed within 0.5 m (M = max frames,
                   H = the route's number of waypoints) + ``reward_step`` -0.1 + ``reward_collision`` -50
                   on a collision (the episode then terminates)
Episode            terminates on a collision or once the last waypoint is reached or skipped; truncated
                   after M steps (``default``: M = 250, 60-120 waypoints; ``paper``: M = 1000, 800-1200)
info               ``position`` (2,) car centre, ``waypoint`` (2,) next local waypoint (both in metres,
                   town frame), the three reward terms, ``waypoint_index``, ``waypoints_reached``,
                   ``num_waypoints``, ``collision``, ``is_success``
=================  ======================================================================================

Observation layout (paper: "heading angle, odometry, linear and angular velocity, 32-beam lidar"):

=========  =============================================================================================
index      meaning (all clipped to [-1, 1])
=========  =============================================================================================
0          sin of the heading error: angle from the car's heading to the next global waypoint
1          cos of the heading error
2          odometry: metres driven / (speed limit * dt * M), in [0, 1]
3          linear velocity, forward (body frame) / speed limit
4          linear velocity, lateral (body frame, + left) / speed limit
5          angular velocity (yaw rate, + counter-clockwise) / (yaw rate at full lock and the speed limit)
6 .. 37    lidar: range / 20 m of beam j at ``yaw + 2 pi j / 32`` (j = 0 straight ahead, counter-clockwise)
=========  =============================================================================================

Local waypoint rule (``info["waypoint"]``, used only by the inverse-dynamics model): the point of the
route ``local_lookahead`` (3 m) ahead of the car's projection on it, but never beyond the next global
waypoint -- with 1.5 m spacing, the next global waypoint not yet reached; with sparse waypoints
(``waypoint_spacing=15.0``) a point between the car and it. A waypoint the car passes farther than
0.5 m away (crossing its perpendicular gate within ``skip_width``) is skipped without reward.

Arguments (``gymnasium.make("shaped_es:CarNav-v0", preset="paper", waypoint_spacing=15.0, ...)``):

=================  =============  =======================================================================
argument           default        meaning
=================  =============  =======================================================================
``render_mode``    ``None``       ``"rgb_array"``: ``render()`` returns a top-down frame (``render.py``)
``preset``         ``"default"``  ``"default"`` (small, learns in minutes) or ``"paper"`` (the paper's sizes)
``**overrides``                   any field of :class:`~shaped_es.envs.carnav.config.CarNavConfig`
=================  =============  =======================================================================

Seeding, ``info`` and the registered entry points (``make_limited``, ``CarNavVectorEnv``): see
:class:`~shaped_es.envs.batch_env.BatchCoreEnv`.
"""

from __future__ import annotations

from shaped_es.envs.batch_env import BatchCoreEnv
from shaped_es.envs.carnav.config import make_config
from shaped_es.envs.carnav.core import CarNavCore
from shaped_es.envs.core import limited_entry_point
from shaped_es.envs.vector import vector_entry_point


class CarNavEnv(BatchCoreEnv):
    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}
    env_id = "CarNav-v0"
    core_cls = CarNavCore
    make_config = staticmethod(make_config)
    obs_bound = 1.0

    def render_frame(self, state):
        from shaped_es.envs.carnav.render import render_top_down

        return render_top_down(self.batch_core, state, 0)


make_limited = limited_entry_point(CarNavEnv)  # the registered entry point
CarNavVectorEnv = vector_entry_point(CarNavEnv)  # the registered vector_entry_point
