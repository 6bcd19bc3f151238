"""Typed settings of UR5Reach-v0 with two presets, ``paper`` and ``default``.

Paper values (Sec. IV, "UR5 Robot arm in ROS Gazebo", and the shared reward of Sec. IV): horizon
H = max frames M = 100 Bezier points, control point P1 = (0.75, 0.15, 0.45), waypoint reached within
0.1, reward +M/H per waypoint, -0.1 per step, -50 and the end of the episode on a collision, 5-D joint
torques. Everything else (physics, torque scale, target region) is our choice, documented per field.

``paper`` samples the target on the whole upper hemisphere (the paper's words); ``default`` keeps it on
the front half (|azimuth| <= 90 deg, the side of P1), so no Bezier path swings over the base through the
singular cylinder above joint 1 (the hand-written follower scores 90.0 on ``default``, 86.9 on ``paper``
where ~5% of its paths hit the arm). Every field can be overridden through ``gymnasium.make`` kwargs.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

from shaped_es.envs.presets import preset_config

HALF_PI = math.pi / 2

Vec3 = tuple[float, float, float]
Vec5 = tuple[float, float, float, float, float]


@dataclass(frozen=True)
class UR5Config:
    """All numbers of the task. Lengths in metres, angles in radians, torques in N m."""

    # --- episode and reward (paper) ---
    max_steps: int = 100  # M: max frames; the episode is truncated after M steps
    num_waypoints: int = 100  # H: Bezier points t = 0, 1/(H-1), ..., 1 (paper: H = M = 100)
    reach_radius: float = 0.1  # a waypoint counts as reached within this end-effector distance
    step_penalty: float = 0.1  # reward -step_penalty every step
    collision_penalty: float = 50.0  # reward -collision_penalty on a collision
    terminate_on_collision: bool = True  # a collision ends the episode (paper)
    control_point: Vec3 = (0.75, 0.15, 0.45)  # P1 of the quadratic Bezier curve (paper)
    # the waypoints form a timed path (at most one reached a step), which the 13-D observation does not
    # show; True appends the episode's phase steps / max_steps (14-D): a diagnostic of what the labels
    # of a schedule-following controller need (docs/shaped-results.md), not the paper's task
    observe_phase: bool = False

    # --- start and target ---
    # Fixed start: the UR "home" pose (elbow up, tool down) panned +90 deg, end effector P0 at
    # (-0.109, 0.487, 0.432). The paper does not give its start; this one puts P0 0.92 from P1, so only
    # ~6 waypoints lie within reach_radius of the start and standing still earns about -4.
    start_qpos: Vec5 = (HALF_PI, -HALF_PI, HALF_PI, -HALF_PI, -HALF_PI)
    start_qpos_noise: float = 0.0  # uniform +- noise on the start joints (0: the paper's fixed start)
    target_radius: tuple[float, float] = (0.35, 0.75)  # target distance from the base origin
    target_elevation: tuple[float, float] = (0.45, 1.2)  # elevation above the ground plane (rad)
    target_azimuth: tuple[float, float] = (-HALF_PI, HALF_PI)  # azimuth about world z from +x (rad)

    # --- physics ---
    timestep: float = 0.01  # MuJoCo timestep (s); implicitfast integrator
    frame_skip: int = 4  # physics steps per env step (env step = 0.04 s, episode = 4 s)
    torque_limits: Vec5 = (150.0, 150.0, 150.0, 28.0, 28.0)  # action +-1 -> +- these (UR5 joint ratings)
    joint_damping: Vec5 = (47.7, 47.7, 47.7, 8.9, 8.9)  # = torque limit / pi: full torque ~ 180 deg/s max
    armature: Vec5 = (0.0, 0.0, 0.0, 0.0, 0.0)  # reflected rotor inertia added per joint (kg m^2)
    gravity_compensation: float = 1.0  # MuJoCo body gravcomp: 1 cancels the links' weight exactly

    # --- speed (no effect on results) ---
    threads: int = 1  # MuJoCo batch threads per core (1: parallelism comes from worker processes)

    @property
    def waypoint_reward(self) -> float:
        """+M/H for each waypoint reached (paper)."""
        return self.max_steps / self.num_waypoints

    @property
    def control_dt(self) -> float:
        """Seconds per env step."""
        return self.timestep * self.frame_skip

    def validate(self) -> "UR5Config":
        checks = [
            (self.max_steps > 0, "max_steps must be positive"),
            (self.num_waypoints >= 2, "num_waypoints must be >= 2"),
            (self.reach_radius > 0, "reach_radius must be positive"),
            (self.timestep > 0 and self.frame_skip > 0, "timestep and frame_skip must be positive"),
            (self.threads >= 0, "threads must be >= 0"),
            (0 < self.target_radius[0] <= self.target_radius[1], "target_radius must be 0 < lo <= hi"),
            (0 <= self.target_elevation[0] <= self.target_elevation[1] <= HALF_PI,
             "target_elevation must satisfy 0 <= lo <= hi <= pi/2 (upper hemisphere)"),
            (self.target_azimuth[0] <= self.target_azimuth[1], "target_azimuth must be lo <= hi"),
            (all(t > 0 for t in self.torque_limits), "torque_limits must be positive"),
            (all(d >= 0 for d in self.joint_damping), "joint_damping must be >= 0"),
            (all(a >= 0 for a in self.armature), "armature must be >= 0"),
        ]
        sizes = {"control_point": 3, "start_qpos": 5, "torque_limits": 5, "joint_damping": 5, "armature": 5,
                 "target_radius": 2, "target_elevation": 2, "target_azimuth": 2}
        for name, n in sizes.items():
            if len(getattr(self, name)) != n:
                raise ValueError(f"UR5Reach-v0: {name} needs {n} numbers, got {getattr(self, name)!r}")
        for ok, msg in checks:
            if not ok:
                raise ValueError(f"UR5Reach-v0: {msg}")
        return self

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


PRESETS: dict[str, UR5Config] = {
    "paper": UR5Config(target_azimuth=(-math.pi, math.pi)),
    "default": UR5Config(),
}


def make_config(preset: str = "default", **overrides: Any) -> UR5Config:
    """A preset with ``overrides`` applied (lists become tuples); one-line ``ValueError`` on bad input."""
    return preset_config("UR5Reach-v0", PRESETS, preset, overrides)
