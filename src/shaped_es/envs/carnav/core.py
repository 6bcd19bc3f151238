"""Batched core of CarNav-v0: B cars, pure ``state in -> state out`` (protocol in ``envs/core.py``).

One Numba kernel call per step runs, car by car: the kinematic bicycle (``vehicle.py``), the collision
of the car's rectangle with the town's boxes and the 32-beam lidar (``lidar.py``, over a per-cell
index), the waypoint rules (``waypoints.py``: reached / skipped / local waypoint) and the observation.
A single call keeps the per-step Python overhead small, so small batches (a worker's chunk of the
population) stay fast too.

Rewards (paper Sec. IV), returned as named terms that sum to the reward: ``reward_waypoint`` = +M/H per
global waypoint reached (M = ``max_steps``, H = this route's number of waypoints), ``reward_step`` =
-0.1 every step, ``reward_collision`` = -50 on a collision, which ends the episode (``terminated``);
reaching or skipping the last waypoint also ends it (``terminate_at_goal``); ``truncated`` after M
steps. Cars that have ended are frozen (zero reward, same flags, same observation) until ``reset``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numba as nb
import numpy as np

from shaped_es.envs.carnav import vehicle as vh
from shaped_es.envs.carnav.config import CarNavConfig
from shaped_es.envs.carnav.controller import pure_pursuit
from shaped_es.envs.carnav.lidar import beam_directions, cell_of, collides, scan_into
from shaped_es.envs.carnav.observation import state_obs
from shaped_es.envs.carnav.planner import plan_routes
from shaped_es.envs.carnav.town import TownPack, town_pack
from shaped_es.envs.carnav.waypoints import advance, global_index, local_index

ACT_DIM = 2  # steer, throttle
IDX_FIELDS = ("k", "progress", "local", "reached", "steps")
K, PROGRESS, LOCAL, REACHED, STEPS = range(5)  # columns of ``idx`` (B, 5)


@dataclass(frozen=True)
class CarNavState:
    """State of B cars. ``route`` is shared by all states of an episode (never written after reset)."""

    town: np.ndarray  # (B,) int64 town of each car
    route: np.ndarray  # (B, D, 2) float64 dense route (planner.py), first n_dense points valid
    n_dense: np.ndarray  # (B,) int64
    num_wp: np.ndarray  # (B,) int64 H: global waypoints of the route
    car: np.ndarray  # (B, 8) float64 x, y, yaw, v, v_lat, yaw_rate, steer, odometer (vehicle.CAR_FIELDS)
    idx: np.ndarray  # (B, 5) int64 k (next global waypoint, 1..H+1), progress, local (dense indices),
    #                  reached (waypoints rewarded), steps
    flags: np.ndarray  # (B, 2) bool terminated, truncated
    obs: np.ndarray  # (B, obs_dim) float32 last observation

    @property
    def batch_size(self) -> int:
        return int(self.car.shape[0])

    def __getattr__(self, name: str) -> np.ndarray:  # named views: state.x, state.v, state.k, ...
        if name in vh.CAR_FIELDS:
            return self.car[:, vh.CAR_FIELDS.index(name)]
        if name in IDX_FIELDS:
            return self.idx[:, IDX_FIELDS.index(name)]
        if name in ("terminated", "truncated"):
            return self.flags[:, ("terminated", "truncated").index(name)]
        raise AttributeError(name)

    def route_waypoints(self, i: int, stride: int) -> np.ndarray:
        """Global waypoints ``(H, 2)`` of car ``i``."""
        n = int(self.n_dense[i])
        return self.route[i, np.minimum(np.arange(1, int(self.num_wp[i]) + 1) * stride, n - 1)]


@nb.njit(cache=True)
def _kernel(move, action, town, route, n_dense, num_wp, car, idx, flags, prev_obs, boxes, origin, cell_start,
            cell_items, beam_cos, beam_sin, par, ipar, car_out, idx_out, flags_out, obs, terms, reward,
            collided, waypoint):
    """Advance every car by one step (``move``) or just observe it (reset); writes the ``*_out`` rows,
    ``obs`` (B, 6 + beams), reward ``terms`` (B, 3), ``reward``, ``collided`` and the local ``waypoint``."""
    nbeam = beam_cos.shape[0]
    inv_x, inv_y, ranges = np.empty(nbeam), np.empty(nbeam), np.empty(nbeam)
    stride, rng = ipar[vh.I_STRIDE], par[vh.P_RANGE]
    for i in range(car.shape[0]):
        car_out[i], idx_out[i], flags_out[i] = car[i], idx[i], flags[i]
        terms[i, 0], terms[i, 1], terms[i, 2], reward[i], collided[i] = 0.0, 0.0, 0.0, 0.0, False
        n, H, t = n_dense[i], num_wp[i], town[i]
        if move and (flags[i, 0] or flags[i, 1]):  # ended: frozen
            obs[i] = prev_obs[i]
            waypoint[i] = route[i, idx[i, LOCAL]]
            continue
        c_in, c = car[i], car_out[i]
        if move:
            vh.bicycle(c_in, action[i, 0], action[i, 1], par, c)
        cell = cell_of(c[vh.X], c[vh.Y], origin[t, 0], origin[t, 1], par[vh.P_CELL], ipar[vh.I_GX],
                       ipar[vh.I_GY])
        i0, i1 = (cell_start[t, cell], cell_start[t, cell + 1]) if cell >= 0 else (0, 0)
        k, got = idx[i, K], 0
        if move:
            hit = cell < 0 or collides(c[vh.X], c[vh.Y], c[vh.YAW], par[vh.P_HALF_LEN], par[vh.P_HALF_WID],
                                       boxes[t], cell_items[t], i0, i1)
            k, got = advance(c_in[vh.X], c_in[vh.Y], c[vh.X], c[vh.Y], route[i], n, stride, k, H,
                             par[vh.P_REACH], par[vh.P_SKIP])
            steps = idx[i, STEPS] + 1
            terms[i, 0] = got * par[vh.P_M] / H  # +M/H per waypoint (paper)
            terms[i, 1] = -par[vh.P_STEP_PENALTY]
            terms[i, 2] = -par[vh.P_COLL_PENALTY] if hit else 0.0
            reward[i] = terms[i, 0] + terms[i, 1] + terms[i, 2]
            ended = hit or (ipar[vh.I_GOAL_ENDS] != 0 and k > H)
            flags_out[i, 0], flags_out[i, 1] = ended, (not ended) and steps >= ipar[vh.I_MAX_STEPS]
            collided[i], idx_out[i, STEPS], idx_out[i, REACHED] = hit, steps, idx[i, REACHED] + got
        g = global_index(min(k, H), stride, n)
        p, loc = local_index(c[vh.X], c[vh.Y], route[i], n, idx[i, PROGRESS], g, ipar[vh.I_AHEAD])
        idx_out[i, K], idx_out[i, PROGRESS], idx_out[i, LOCAL] = k, p, loc
        waypoint[i] = route[i, loc]
        # observation: heading error to the next global waypoint, odometry, velocities (observation.py), lidar
        v_long = math.sqrt(max(c[vh.V] ** 2 - c[vh.V_LAT] ** 2, 0.0))
        state_obs(c[vh.X], c[vh.Y], c[vh.YAW], c[vh.ODOMETER], v_long, c[vh.V_LAT], c[vh.YAW_RATE],
                  route[i, g, 0], route[i, g, 1], par[vh.P_ODO_SCALE], par[vh.P_V_SCALE], par[vh.P_W_SCALE],
                  obs[i])
        scan_into(c[vh.X], c[vh.Y], c[vh.YAW], beam_cos, beam_sin, boxes[t], cell_items[t], i0, i1, rng,
                  inv_x, inv_y, ranges)
        for j in range(nbeam):
            obs[i, 6 + j] = ranges[j] / rng


class CarNavCore:
    """B cars in procedurally generated towns (``BatchCore`` protocol of ``shaped_es.envs.core``)."""

    act_dim = ACT_DIM
    pos_dim = 2

    def __init__(self, config: CarNavConfig | None = None):
        self.config = cfg = (config or CarNavConfig()).validate()
        self.obs_dim = cfg.obs_dim
        self.max_steps = cfg.max_steps
        self.pack: TownPack = town_pack(cfg)
        self._beam_cos, self._beam_sin = beam_directions(cfg.lidar_beams)
        self._par, self._ipar = vh.kernel_params(cfg, self.pack.grid_shape, self.pack.cell)

    def _run(self, move: bool, s: CarNavState, action: np.ndarray):
        B, pk = s.batch_size, self.pack
        car, idx, flags = np.empty_like(s.car), np.empty_like(s.idx), np.empty_like(s.flags)
        obs, terms = np.empty((B, self.obs_dim), np.float32), np.empty((B, 3))
        reward, collided, waypoint = np.empty(B), np.empty(B, np.bool_), np.empty((B, 2))
        _kernel(move, action, s.town, s.route, s.n_dense, s.num_wp, s.car, s.idx, s.flags, s.obs, pk.boxes,
                pk.origin, pk.cell_start, pk.cell_items, self._beam_cos, self._beam_sin, self._par,
                self._ipar, car, idx, flags, obs, terms, reward, collided, waypoint)
        s = replace(s, car=car, idx=idx, flags=flags, obs=obs)
        info = {
            "position": car[:, :2].copy(),  # (B, 2) car centre
            "waypoint": waypoint,  # (B, 2) next local waypoint
            "reward_waypoint": terms[:, 0],
            "reward_step": terms[:, 1],
            "reward_collision": terms[:, 2],
            "waypoint_index": idx[:, K].copy(),
            "waypoints_reached": idx[:, REACHED].copy(),
            "num_waypoints": s.num_wp,
            "collision": collided,
            "is_success": idx[:, REACHED] == s.num_wp,
        }
        return s, obs.copy(), reward, info

    def reset(self, seeds: np.ndarray) -> tuple[CarNavState, np.ndarray, dict[str, np.ndarray]]:
        cfg = self.config
        town, route, n_dense = plan_routes(self.pack, cfg, seeds)
        B = town.shape[0]
        car = np.zeros((B, len(vh.CAR_FIELDS)))
        car[:, vh.X], car[:, vh.Y] = route[:, 0, 0], route[:, 0, 1]
        car[:, vh.YAW] = np.arctan2(route[:, 1, 1] - route[:, 0, 1], route[:, 1, 0] - route[:, 0, 0])
        idx = np.zeros((B, len(IDX_FIELDS)), np.int64)
        idx[:, K] = 1
        num_wp = (n_dense - 2) // cfg.wp_stride + 1  # H = ceil((n - 1) / stride)
        s = CarNavState(town=town, route=route, n_dense=n_dense, num_wp=num_wp, car=car, idx=idx,
                        flags=np.zeros((B, 2), np.bool_), obs=np.zeros((B, self.obs_dim), np.float32))
        s, obs, _, info = self._run(False, s, np.zeros((B, ACT_DIM), np.float32))
        return s, obs, info

    def step(self, state: CarNavState, action: np.ndarray):
        act = np.ascontiguousarray(action, dtype=np.float32).reshape(state.batch_size, ACT_DIM)  # (B, 2)
        s, obs, reward, info = self._run(True, state, act)
        return s, obs, reward, s.flags[:, 0].copy(), s.flags[:, 1].copy(), info

    def waypoint_controller(self, state: CarNavState, obs: np.ndarray, info: dict) -> np.ndarray:
        """The env's scripted waypoint follower (``envs/core.py`` hook): pure pursuit of
        ``info["waypoint"]`` (``controller.py``) -> ``(B, 2)`` in ``[-1, 1]``."""
        return pure_pursuit(self.config, state.yaw, state.v, info["position"], info["waypoint"])
