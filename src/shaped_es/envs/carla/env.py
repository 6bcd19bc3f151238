"""``CarlaNav-v0``: the paper's driving task (Sec. IV, "Carla Driving simulator") on a real CARLA 0.9.16
server through the official ``carla`` client (``pip install -e '.[carla]'``; the client must match the
server's version, checked at connect).

Same contract as ``CarNav-v0`` (``carnav/env.py``): the 2-D action (steer +1 = full left, throttle,
negative brakes; 25 km/h enforced by braking), the 38-D observation with the same layout, order and
scales, the reward terms (+M/H per global waypoint within 0.5 m, -0.1 per step, -50 and the end of the
episode on a collision sensor event), the waypoint rules, and ``info`` (``position`` and ``waypoint``
in metres in CarNav-v0's right-handed frame: CARLA's ``(x, -y)``; ``frame.py``). So a policy's input
means the same on both envs.

Episode (``reset(seed)``): the seed orders the town's spawn points; the first whose vehicle spawns
(a blocked one is skipped, ``spawn_tries``) is the start, and seeded destinations among the other
spawn points are tried until the route (``routes.py``: A* over ``Map.get_topology()``) has a length in
``route_length`` (else the closest); the route is resampled every 0.5 m and its global waypoints are
every ``waypoint_spacing`` (1.5 m). The car is braked for ``settle_ticks`` ticks (it drops onto the
road), then the first observation is taken. Each ``step`` applies one ``VehicleControl``, ticks the
synchronous world once (``dt`` = 0.1 s) and reads that frame's lidar measurement.

Connection (``connection.py``): the first ``reset`` connects to ``host:port + 3 * worker index``
(``config.py``); making the env needs no server, only the ``carla`` package. Actors are destroyed on
reset and close, also after an exception; the server's settings are restored on close and after an
error. A dead server raises ``CarlaServerLost`` from ``reset``/``step`` within the timeouts.

Envs of one process that talk to one server take turns (``metadata["serial_episodes"]``: the rollout
layer runs their episodes one after another instead of in lock-step).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import replace
from typing import Any

import gymnasium as gym
import numpy as np

from shaped_es.envs.carla.actors import EgoActors
from shaped_es.envs.carla.config import ENV_ID, make_config, server_address
from shaped_es.envs.carla.connection import (CarlaError, CarlaServerLost, Session, acquire, first_line,
                                             import_carla, release)
from shaped_es.envs.carla.frame import body_velocity, location_xyz, yaw_of, yaw_rate_of
from shaped_es.envs.carla.routes import Located, RoadGraph, pick_route, topology_segments, waypoint_key
from shaped_es.envs.carla.terms import CarState, RouteProgress, control_values, observation, reward_terms
from shaped_es.envs.carnav.planner import _resample
from shaped_es.envs.core import EPISODE_SEED_HIGH, SERIAL_EPISODES_KEY, limited_entry_point


def dense_route(polyline: np.ndarray, step: float) -> np.ndarray:
    """A route polyline ``(m, 2)`` resampled every ``step`` metres (CarNav-v0's ``_resample``)."""
    poly = np.ascontiguousarray(polyline, dtype=np.float64)
    length = float(np.hypot(*np.diff(poly, axis=0).T).sum())
    out = np.empty((int(math.ceil(length / step)) + 2, 2))
    return out[: _resample(poly, len(poly), step, out)].copy()


class CarlaNavEnv(gym.Env):
    metadata = {"render_modes": [], "render_fps": 10, SERIAL_EPISODES_KEY: True}
    env_id = ENV_ID

    def __init__(self, render_mode: str | None = None, preset: str = "default", **overrides: Any):
        if render_mode is not None:
            raise ValueError(f"{ENV_ID} does not render (watch the CARLA server's window instead)")
        self.config = cfg = make_config(preset, **overrides)
        self.carla = import_carla()  # one clear line without the package; no server needed yet
        self.host, self.port = server_address(cfg)
        self.metadata = {**self.metadata, "render_fps": int(round(1.0 / cfg.dt))}
        self.render_mode = None
        self.observation_space = gym.spaces.Box(-1.0, 1.0, (cfg.obs_dim,), np.float32)
        self.action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)
        self._session: Session | None = None
        self._actors: EgoActors | None = None
        self._progress: RouteProgress | None = None
        self._car: CarState | None = None
        self._steps = 0
        self._ended_by: str | None = None  # why the episode can no longer step (None: it can)

    @property
    def address(self) -> str:
        return f"{self.host}:{self.port}"

    # -- episode -----------------------------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        episode_seed = seed if seed is not None else int(self.np_random.integers(EPISODE_SEED_HIGH))
        rng = np.random.default_rng(episode_seed)
        with self._guard():
            if self._session is None or self._session.closed:
                self._session = acquire(self.carla, self.host, self.port, self.config, self)
            session = self._session
            session.claim(self)
            self._drop_actors()
            graph, spawns, spots = self._map_data(session)
            self._progress, self._actors = self._start(session, graph, spawns, spots, rng)
            self._ended_by = None
            for _ in range(max(1, self.config.settle_ticks)):
                self._actors.vehicle.apply_control(self.carla.VehicleControl(throttle=0.0, steer=0.0, brake=1.0))
                frame = session.tick()
            self._car = self._read_car(0.0)
            ranges = self._actors.ranges(frame)
            self._actors.collided(frame)  # a bump while settling is not the agent's
            self._steps = 0
            self._progress.locate(self._car.x, self._car.y)
            obs = observation(self._car, self._progress.route[self._progress.goal_index()], ranges, self.config)
            return obs, self._info(0.0, 0.0, 0.0, False)

    def _map_data(self, session: Session) -> tuple[RoadGraph, list, list[Located]]:
        """The road graph, spawn points and their places on the graph (cached per session)."""
        key = f"map:{self.config.town}:{self.config.dense_step:g}"
        if key not in session.cache:
            graph = RoadGraph(topology_segments(session.map, self.config.dense_step))
            spawns = list(session.map.get_spawn_points())
            spots = [graph.locate(location_xyz(t.location)[:2],
                                  waypoint_key(session.map.get_waypoint(t.location))) for t in spawns]
            session.cache[key] = (graph, spawns, spots)
        return session.cache[key]

    def _start(self, session: Session, graph: RoadGraph, spawns: list, spots: list[Located],
               rng: np.random.Generator) -> tuple[RouteProgress, EgoActors]:
        cfg = self.config
        for start in rng.permutation(len(spawns))[: cfg.spawn_tries]:
            line = pick_route(graph, spots, int(start), rng, cfg.route_length, cfg.route_tries)
            if line is None:
                continue
            actors = EgoActors.spawn(session, spawns[int(start)], cfg)
            if actors is not None:
                return RouteProgress(dense_route(line, cfg.dense_step), cfg), actors
        raise CarlaError(f"{ENV_ID}: no free spawn point with a route in {cfg.spawn_tries} tries on "
                         f"{cfg.town} at {self.address} ({len(spawns)} spawn points)")

    def step(self, action):
        if self._actors is None or self._progress is None:
            why = f": {self._ended_by}" if self._ended_by else ""
            raise RuntimeError(f"{ENV_ID}: call reset() before step(){why}")
        steer, throttle = np.asarray(action, dtype=np.float64).reshape(2)
        with self._guard():
            s, g, b = control_values(steer, throttle, self._car.speed, self.config)
            self._actors.vehicle.apply_control(self.carla.VehicleControl(throttle=g, steer=s, brake=b))
            frame = self._session.tick()
            ranges = self._actors.ranges(frame)
            hit = self._actors.collided(frame)
            prev, car = self._car, self._read_car(0.0)
            car = replace(car, odometer=prev.odometer + math.hypot(car.x - prev.x, car.y - prev.y))
            self._car, self._steps = car, self._steps + 1
            got = self._progress.move(prev.x, prev.y, car.x, car.y)
            self._progress.locate(car.x, car.y)
            terms = reward_terms(got, self._progress.num_waypoints, hit, self.config)
            terminated = hit or (self.config.terminate_at_goal and self._progress.done)
            truncated = not terminated and self._steps >= self.config.max_steps
            obs = observation(car, self._progress.route[self._progress.goal_index()], ranges, self.config)
            return obs, float(sum(terms)), bool(terminated), bool(truncated), self._info(*terms, hit)

    def _read_car(self, odometer: float) -> CarState:
        v = self._actors.vehicle
        t = v.get_transform()
        xyz, yaw = location_xyz(t.location), yaw_of(t.rotation)
        v_long, v_lat = body_velocity(v.get_velocity(), yaw)
        return CarState(float(xyz[0]), float(xyz[1]), yaw, v_long, v_lat, yaw_rate_of(v.get_angular_velocity()),
                        odometer)

    def _info(self, r_wp: float, r_step: float, r_coll: float, hit: bool) -> dict[str, Any]:
        p, car = self._progress, self._car
        return {
            "position": np.array([car.x, car.y]),  # (2,) car (actor) location
            "waypoint": p.waypoint(),  # (2,) next local waypoint
            "reward_waypoint": float(r_wp),
            "reward_step": float(r_step),
            "reward_collision": float(r_coll),
            "waypoint_index": int(p.k),
            "waypoints_reached": int(p.reached),
            "num_waypoints": int(p.num_waypoints),
            "collision": bool(hit),
            "is_success": bool(p.reached == p.num_waypoints),
        }

    # -- actors, faults and clean-up ---------------------------------------------------------------
    @contextmanager
    def _guard(self) -> Iterator[None]:
        """On any exception: actors destroyed and the server's settings restored, then the error raised
        (a ``RuntimeError`` of the client, i.e. a call that timed out, as :class:`CarlaServerLost`)."""
        try:
            yield
        except CarlaServerLost:
            self._abort(lost=True)
            raise
        except CarlaError:
            self._abort(lost=False)
            raise
        except RuntimeError as exc:  # the carla client raises RuntimeError when a call times out
            self._abort(lost=True)
            raise CarlaServerLost(f"{ENV_ID}: the CARLA server at {self.address} stopped answering "
                                  f"({first_line(exc)})") from exc
        except BaseException:
            self._abort(lost=False)
            raise

    def _abort(self, lost: bool) -> None:
        session, self._session = self._session, None
        if session is not None:
            session.close(lost=lost)  # ends every user's episode (this one too) and restores settings
            release(session, self)
        self._drop_actors()
        self._ended_by = "the previous reset or step failed"

    def preempt(self) -> None:
        """Another env of this process took the server (or its session closed): end this episode."""
        self._drop_actors()
        self._ended_by = "another CarlaNav-v0 env of this process reset on the same server"

    def _drop_actors(self) -> None:
        actors, self._actors, self._progress = self._actors, None, None
        if actors is not None:
            try:
                actors.destroy()
            except RuntimeError:  # the server is gone: nothing left to destroy
                pass

    def close(self):
        self._drop_actors()
        if self._session is not None:
            release(self._session, self)
            self._session = None
        super().close()


make_limited = limited_entry_point(CarlaNavEnv)  # the registered entry point
