"""Typed settings of CarNav-v0 with two presets, ``paper`` and ``default``; ``NavTaskConfig`` holds the task
fields CarlaNav-v0 (``envs/carla``) shares, so both envs read one definition of episode, reward and scales.

Paper values (Sec. IV, "Carla Driving simulator", and the shared reward of Sec. IV): global planner
waypoints every 1.5 m, 800-1200 waypoints per episode, M = 1000 max frames, a waypoint is reached within
0.5 m, reward +M/H per waypoint (H = the episode's number of waypoints), -0.1 per step, -50 and the end
of the episode on a collision, a 25 km/h speed limit enforced by automatic braking, a 38-D state with a
32-beam lidar and a 2-D action (steer, throttle). The town (procedural, CARLA Town07 stands in), the
vehicle model and the lidar range are our choices, documented per field.

Route lengths are set in metres (``route_length``), so the sparse-waypoint ablation of the paper
(planner resolution / 10: ``waypoint_spacing=15.0``) keeps the same routes with 10x fewer, 10x more
rewarding waypoints. ``paper`` routes of 1200-1800 m hold 800-1200 waypoints at 1.5 m.

``default`` is a small town with short routes (60-120 waypoints, M = 250) so a few minutes of ES on a
laptop learns to follow the road. Every field can be overridden through ``gymnasium.make`` kwargs.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

from shaped_es.envs.presets import preset_config

KMH = 1.0 / 3.6  # km/h -> m/s


@dataclass(frozen=True)
class NavTaskConfig:
    """The driving task shared by CarNav-v0 and CarlaNav-v0 (``envs/carla``): episode, reward, waypoint
    rules and the observation's scales, so a policy's input and return mean the same on both. Lengths
    in metres, times in seconds, angles in radians."""

    # --- episode and reward (paper) ---
    max_steps: int = 250  # M: max frames; the episode is truncated after M steps
    waypoint_spacing: float = 1.5  # global planner resolution: a global waypoint every this many metres
    reach_radius: float = 0.5  # a waypoint is reached when the car's centre passes within this distance
    step_penalty: float = 0.1  # reward -step_penalty every step
    collision_penalty: float = 50.0  # reward -collision_penalty on a collision (the episode ends)
    route_length: tuple[float, float] = (90.0, 180.0)  # driven route length range (60-120 wp at 1.5 m)
    route_tries: int = 256  # start/destination pairs tried per episode to hit route_length
    skip_width: float = 3.5  # crossing a waypoint's gate line farther than reach_radius but within this
    #                          lateral distance skips it without reward (the car never has to turn back)
    local_lookahead: float = 3.0  # local waypoint: at most this far ahead (along the route) of the car
    terminate_at_goal: bool = True  # the episode ends once the last waypoint is reached or skipped

    # --- vehicle: step, controls and the observation's scales (observation.py) ---
    dt: float = 0.1  # seconds per step
    wheelbase: float = 2.7  # front to rear axle
    rear_to_center: float = 1.35  # rear axle to the reference point (centre of the car)
    max_steer: float = math.radians(35.0)  # steer action +-1 -> +- this front wheel angle
    max_accel: float = 3.0  # throttle +1 -> this acceleration (m/s^2)
    max_brake: float = 8.0  # throttle -1 -> this deceleration (m/s^2)
    speed_limit: float = 25.0 * KMH  # 25 km/h (paper); above it the brake is applied automatically
    auto_brake: float = 8.0  # automatic braking deceleration above the speed limit (m/s^2)

    # --- lidar ---
    lidar_beams: int = 32  # beams over 360 degrees (paper: 32; the observation is 6 + beams)
    lidar_range: float = 20.0  # readings are range / lidar_range in [0, 1]

    env_id = "CarNav-v0"  # names the env in error messages (a class attribute, not a field)

    @property
    def obs_dim(self) -> int:
        return 6 + self.lidar_beams

    @property
    def dense_step(self) -> float:
        """Spacing of the dense route polyline: waypoint_spacing / stride, at most 0.5 m."""
        return self.waypoint_spacing / self.wp_stride

    @property
    def wp_stride(self) -> int:
        """Dense route points per global waypoint."""
        return max(1, int(math.ceil(self.waypoint_spacing / 0.5 - 1e-9)))

    def task_checks(self) -> list[tuple[bool, str]]:
        """(holds, message) of every rule on the shared fields."""
        lo, hi = self.route_length
        return [
            (self.max_steps > 0, "max_steps must be positive"),
            (self.waypoint_spacing > 0 and self.reach_radius > 0,
             "waypoint_spacing and reach_radius must be positive"),
            (0 < lo <= hi, "route_length must be 0 < lo <= hi"),
            (self.route_tries >= 1, "route_tries must be >= 1"),
            (self.skip_width >= self.reach_radius, "skip_width must be >= reach_radius"),
            (self.local_lookahead > 0, "local_lookahead must be positive"),
            (self.dt > 0 and self.wheelbase > 0 and 0 < self.rear_to_center < self.wheelbase,
             "dt, wheelbase must be > 0 and 0 < rear_to_center < wheelbase"),
            (0 < self.max_steer < math.pi / 2, "max_steer must be in (0, pi/2)"),
            (min(self.max_accel, self.max_brake, self.speed_limit, self.auto_brake) > 0,
             "max_accel, max_brake, speed_limit, auto_brake must be positive"),
            (self.lidar_beams >= 1 and self.lidar_range > 0, "lidar_beams, lidar_range must be positive"),
        ]

    def check(self, pairs: tuple[str, ...], checks: list[tuple[bool, str]]):
        """Raise one-line ``ValueError`` (naming ``env_id``) on the first failed check; else self."""
        for name in pairs:
            if len(getattr(self, name)) != 2:
                raise ValueError(f"{self.env_id}: {name} needs 2 numbers, got {getattr(self, name)!r}")
        for ok, msg in checks:
            if not ok:
                raise ValueError(f"{self.env_id}: {msg}")
        return self

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass(frozen=True)
class CarNavConfig(NavTaskConfig):
    """All numbers of CarNav-v0: the shared task plus the procedural town, the car and the renderer."""

    # --- town (procedural stand-in for CARLA Town07) ---
    num_towns: int = 16  # towns in the family; an episode's town is chosen by its seed
    town_seed: int = 0  # seed of the town family (town i uses [town_seed, i])
    grid_nodes: tuple[int, int] = (5, 5)  # intersections along x and y
    block_size: tuple[float, float] = (32.0, 48.0)  # distance between neighbouring intersections
    road_width: float = 7.0  # two lanes of 3.5 m
    lane_offset: float = 1.75  # route runs this far right of the road centre line (0: on the centre line)
    setback: float = 2.0  # verge between the road edge and the building line
    edge_drop: float = 0.15  # fraction of road segments closed (the town stays connected)
    buildings_per_block: tuple[int, int] = (1, 4)  # buildings per block (split with alleys)
    empty_lot_prob: float = 0.1  # probability that a block has no building
    props_per_block: tuple[int, int] = (0, 3)  # small obstacles (poles, bins) on a block's verge
    turn_radius: float = 6.0  # the planner rounds every 90-degree turn with an arc of this radius
    wall_thickness: float = 2.0  # boundary wall around the town

    # --- vehicle (kinematic bicycle; the shared fields are NavTaskConfig's) ---
    car_length: float = 4.5  # footprint used for collisions
    car_width: float = 1.9
    coast_decel: float = 0.3  # rolling resistance (m/s^2) while moving

    # --- lidar ---
    lidar_cell: float = 4.0  # cell of the spatial index (each cell lists the boxes within range)

    # --- rendering (no effect on results) ---
    render_size: int = 512  # image side (pixels)
    render_window: float = 60.0  # side of the car-centred view (m); 0 renders the whole town

    @property
    def route_buffer(self) -> int:
        """Dense route points stored per car (routes longer than the upper bound are cut)."""
        return int(math.ceil(1.3 * self.route_length[1] / self.dense_step)) + 64

    def validate(self) -> "CarNavConfig":
        hw = self.road_width / 2
        checks = self.task_checks() + [
            (self.num_towns >= 1, "num_towns must be >= 1"),
            (min(self.grid_nodes) >= 2, "grid_nodes must be >= 2 in both directions"),
            (self.block_size[0] >= 2 * (hw + self.setback + self.turn_radius) + 4,
             "block_size is too small for the road width, setback and turn radius"),
            (self.block_size[0] <= self.block_size[1], "block_size must be lo <= hi"),
            (0 <= self.lane_offset < hw - self.car_width / 2, "lane_offset must keep the car on the road"),
            (0 <= self.edge_drop < 1 and 0 <= self.empty_lot_prob <= 1,
             "edge_drop must be in [0, 1) and empty_lot_prob in [0, 1]"),
            (1 <= self.buildings_per_block[0] <= self.buildings_per_block[1] <= 4,
             "buildings_per_block must satisfy 1 <= lo <= hi <= 4"),
            (0 <= self.props_per_block[0] <= self.props_per_block[1],
             "props_per_block must be 0 <= lo <= hi"),
            (self.turn_radius >= self.wheelbase / math.tan(self.max_steer) + 0.5,
             "turn_radius must exceed the car's minimum turning radius"),
            (self.coast_decel >= 0, "coast_decel must be >= 0"),
            (self.lidar_cell > 0, "lidar_cell must be positive"),
            (self.render_size >= 32 and self.render_window >= 0, "render_size >= 32, render_window >= 0"),
        ]
        return self.check(("route_length", "grid_nodes", "block_size", "buildings_per_block",
                           "props_per_block"), checks)


PRESETS: dict[str, CarNavConfig] = {
    # Paper: M = 1000, 800-1200 waypoints at 1.5 m (1200-1800 m routes), 0.5 m radius; a large town.
    "paper": CarNavConfig(max_steps=1000, route_length=(1200.0, 1800.0), num_towns=8, grid_nodes=(14, 14),
                          block_size=(50.0, 90.0), lidar_cell=5.0),
    # Small and quick: 60-120 waypoints, M = 250 (a car at the speed limit drives ~170 m in 250 steps).
    "default": CarNavConfig(),
}


def make_config(preset: str = "default", **overrides: Any) -> CarNavConfig:
    """A preset with ``overrides`` applied (lists become tuples); one-line ``ValueError`` on bad input."""
    return preset_config("CarNav-v0", PRESETS, preset, overrides)
