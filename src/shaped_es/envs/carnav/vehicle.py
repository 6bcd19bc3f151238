"""Vehicle model of CarNav-v0: a kinematic bicycle about the car's centre (Rajamani, *Vehicle Dynamics
and Control*, Sec. 2.2, front-wheel steering), fixed step ``dt``, semi-implicit Euler::

    delta = steer * max_steer                        beta = atan(l_r / L * tan(delta))   (side slip)
    a = throttle * (max_accel if throttle >= 0 else max_brake) - coast_decel  (coast only if moving)
    a = min(a, -auto_brake)   if v > speed_limit     (paper: a brake is applied above 25 km/h)
    v' = max(v + a dt, 0)                            (no reverse gear)
    x' = x + v' cos(yaw + beta) dt    y' = y + v' sin(yaw + beta) dt
    yaw' = yaw + v' sin(beta) / l_r dt

The per-car state is one float64 row ``car`` with the columns below; the kernel's scalar settings are
one float64 vector ``par`` (indices ``P_*``) built by :func:`kernel_params` from the config.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from shaped_es.envs.carnav.config import CarNavConfig
from shaped_es.envs.carnav.observation import obs_scales

CAR_FIELDS = ("x", "y", "yaw", "v", "v_lat", "yaw_rate", "steer", "odometer")
X, Y, YAW, V, V_LAT, YAW_RATE, STEER, ODOMETER = range(8)  # columns of ``car`` (B, 8)

(P_DT, P_MAX_STEER, P_ACCEL, P_BRAKE, P_COAST, P_V_LIMIT, P_AUTO_BRAKE, P_LR, P_BETA_GAIN, P_HALF_LEN,
 P_HALF_WID, P_REACH, P_SKIP, P_RANGE, P_CELL, P_ODO_SCALE, P_V_SCALE, P_W_SCALE, P_M, P_STEP_PENALTY,
 P_COLL_PENALTY) = range(21)
(I_GX, I_GY, I_STRIDE, I_AHEAD, I_MAX_STEPS, I_GOAL_ENDS) = range(6)


def kernel_params(cfg: CarNavConfig, grid_shape: tuple[int, int], cell: float):
    """(``par`` float64 ``(21,)``, ``ipar`` int64 ``(6,)``): the step kernel's settings."""
    lr = cfg.rear_to_center
    beta_gain = lr / cfg.wheelbase
    par = np.zeros(21)
    par[[P_DT, P_MAX_STEER, P_ACCEL, P_BRAKE, P_COAST, P_V_LIMIT, P_AUTO_BRAKE, P_LR, P_BETA_GAIN]] = (
        cfg.dt, cfg.max_steer, cfg.max_accel, cfg.max_brake, cfg.coast_decel, cfg.speed_limit, cfg.auto_brake,
        lr, beta_gain)
    par[[P_HALF_LEN, P_HALF_WID, P_REACH, P_SKIP, P_RANGE, P_CELL]] = (
        cfg.car_length / 2, cfg.car_width / 2, cfg.reach_radius, cfg.skip_width, cfg.lidar_range, cell)
    par[[P_ODO_SCALE, P_V_SCALE, P_W_SCALE]] = obs_scales(cfg)  # observation.py
    par[[P_M, P_STEP_PENALTY, P_COLL_PENALTY]] = cfg.max_steps, cfg.step_penalty, cfg.collision_penalty
    ahead = max(1, int(round(cfg.local_lookahead / cfg.dense_step)))
    ipar = np.array([grid_shape[0], grid_shape[1], cfg.wp_stride, ahead, cfg.max_steps,
                     int(cfg.terminate_at_goal)], dtype=np.int64)
    return par, ipar


@nb.njit(cache=True)
def bicycle(car, steer, throttle, par, out):
    """One step of the kinematic bicycle from row ``car`` into row ``out`` (actions clipped to [-1, 1])."""
    steer, throttle = min(1.0, max(-1.0, steer)), min(1.0, max(-1.0, throttle))
    dt, v = par[P_DT], car[V]
    delta = steer * par[P_MAX_STEER]
    acc = throttle * (par[P_ACCEL] if throttle >= 0.0 else par[P_BRAKE])
    if v > 0.0:
        acc -= par[P_COAST]
    if v > par[P_V_LIMIT]:  # paper: automatic brake above the speed limit
        acc = min(acc, -par[P_AUTO_BRAKE])
    v1 = max(v + acc * dt, 0.0)
    beta = math.atan(par[P_BETA_GAIN] * math.tan(delta))  # side-slip angle at the centre
    yaw_rate = v1 * math.sin(beta) / par[P_LR]
    out[X] = car[X] + v1 * math.cos(car[YAW] + beta) * dt
    out[Y] = car[Y] + v1 * math.sin(car[YAW] + beta) * dt
    out[YAW] = (car[YAW] + yaw_rate * dt + math.pi) % (2.0 * math.pi) - math.pi
    out[V], out[V_LAT], out[YAW_RATE], out[STEER] = v1, v1 * math.sin(beta), yaw_rate, delta
    out[ODOMETER] = car[ODOMETER] + v1 * dt
