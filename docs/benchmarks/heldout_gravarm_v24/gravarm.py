"""GravArm-v0: a planar 2-link torque-controlled arm in a VERTICAL plane under gravity.

Written by a helper acting as a new user of shaped-es, from the top-level README alone.

Body
----
* Two uniform rods, l1 = l2 = 0.5 m, m1 = m2 = 1 kg (centre of mass at mid-link, I = m l^2 / 12),
  base at the origin, gravity g = 9.81 m/s^2 along -y. Joint angles: q1 of link 1 from the +x axis,
  q2 of link 2 relative to link 1. q1 = -pi/2, q2 = 0 is hanging straight down (fingertip (0, -1)).
* Joint viscous damping b = 0.5 N m s/rad on both joints.
* Torque control: action in [-1, 1]^2, scaled to tau_max = (14, 4) N m. The largest gravity torques
  (arm stretched horizontally) are 9.81 N m at the shoulder and 2.45 N m at the elbow, so the limits are
  1.43x and 1.63x what holding the arm horizontal takes: enough to hold it up and swing it, not by a
  huge margin. Zero action lets the arm fall and hang.
* Semi-implicit (symplectic) Euler, dt = 0.01 s, 4 substeps per env step (0.04 s), 125 steps (5 s).
  Joint velocities are clipped to +-40 rad/s (a safety net; an undamped free fall reaches ~28).

Task and waypoints
------------------
* Start: q1 = -pi/2 + U(-0.3, 0.3), q2 = U(-0.4, 0.4), at rest (near hanging).
* Target: polar radius U(0.45, 0.95), polar angle U(20 deg, 160 deg): reachable, upper half plane.
* Timed waypoints on the fingertip's Cartesian (x, y): a smooth curve from the start fingertip to the
  target, interpolated in polar coordinates around the base (radius linearly, polar angle the short way
  round), with a smoothstep time profile 3u^2 - 2u^3 over the first 60% of the episode (75 steps), then
  the target held. info["waypoint"] is the scheduled point after the next step (as ReacherWay-v0).
  Polar rather than straight line: the straight line from a hanging start to an upper target passes
  near the base, where the arm would have to fold completely.
* info["position"] = fingertip (x, y).

Observation (13): cos q1, sin q1, cos q2, sin q2, dq1 / 10, dq2 / 10, fingertip x, y, target x, y,
waypoint - fingertip (x, y), phase t / T.

Reward: -|fingertip - target| - 0.05 * |a|^2 per step (a the [-1, 1] action). The task is to reach the
target and hold it there; the schedule only guides the labels (as the README says the built-in timed
arms do), so the reward does not build the label schedule into the objective. The small torque cost
discourages bang-bang holding.

waypoint_controller(obs, info): gravity compensation + Jacobian-transpose PD toward info["waypoint"]
(Cartesian spring toward the waypoint, damping on the fingertip velocity), plus compensation of the
joint damping, clipped to the torque limits.
"""

import math

import gymnasium as gym
import numpy as np

L1, L2 = 0.5, 0.5
M1, M2 = 1.0, 1.0
LC1, LC2 = 0.5 * L1, 0.5 * L2
I1, I2 = M1 * L1 * L1 / 12.0, M2 * L2 * L2 / 12.0
G = 9.81
B = 0.5
TAU_MAX = (14.0, 4.0)
DT = 0.01
SUBSTEPS = 4
MAX_STEPS = 125
SCHEDULE_FRAC = 0.6
QD_MAX = 40.0


def _fingertip(q1, q2):
    return (L1 * math.cos(q1) + L2 * math.cos(q1 + q2), L1 * math.sin(q1) + L2 * math.sin(q1 + q2))


def _gravity(q1, q2):
    c1, c12 = math.cos(q1), math.cos(q1 + q2)
    g2 = M2 * G * LC2 * c12
    g1 = (M1 * LC1 + M2 * L1) * G * c1 + g2
    return g1, g2


class GravArm(gym.Env):
    metadata = {"render_modes": []}

    observation_space = gym.spaces.Box(-np.inf, np.inf, (13,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)

    # fingertip (x, y) does not wrap
    position_period = None

    def __init__(self):
        self.q1 = self.q2 = self.dq1 = self.dq2 = 0.0
        self.t = 0
        self.target = np.zeros(2)
        self.start = np.zeros(2)

    # -- schedule -------------------------------------------------------------------------------------
    def _schedule(self, k):
        """The scheduled fingertip point after k env steps."""
        n = SCHEDULE_FRAC * MAX_STEPS
        u = min(1.0, k / n)
        s = u * u * (3.0 - 2.0 * u)
        r = self._r0 + s * (self._r1 - self._r0)
        a = self._a0 + s * self._da
        return np.array([r * math.cos(a), r * math.sin(a)])

    def _obs_info(self):
        tip = np.array(_fingertip(self.q1, self.q2))
        wp = self._schedule(self.t + 1)
        obs = np.array(
            [
                math.cos(self.q1), math.sin(self.q1), math.cos(self.q2), math.sin(self.q2),
                self.dq1 / 10.0, self.dq2 / 10.0,
                tip[0], tip[1], self.target[0], self.target[1],
                wp[0] - tip[0], wp[1] - tip[1],
                self.t / MAX_STEPS,
            ],
            dtype=np.float32,
        )
        return obs, {"position": tip, "waypoint": wp}

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        rng = self.np_random
        self.q1 = -0.5 * math.pi + float(rng.uniform(-0.3, 0.3))
        self.q2 = float(rng.uniform(-0.4, 0.4))
        self.dq1 = self.dq2 = 0.0
        self.t = 0
        r = float(rng.uniform(0.45, 0.95))
        ang = float(rng.uniform(math.radians(20.0), math.radians(160.0)))
        self.target = np.array([r * math.cos(ang), r * math.sin(ang)])
        self.start = np.array(_fingertip(self.q1, self.q2))
        self._r0 = float(np.hypot(*self.start))
        self._a0 = math.atan2(self.start[1], self.start[0])
        self._r1 = r
        self._da = (ang - self._a0 + math.pi) % (2.0 * math.pi) - math.pi  # the short way round
        return self._obs_info()

    def step(self, action):
        a = np.clip(np.asarray(action, dtype=np.float64).reshape(2), -1.0, 1.0)
        t1, t2 = float(a[0]) * TAU_MAX[0], float(a[1]) * TAU_MAX[1]
        q1, q2, dq1, dq2 = self.q1, self.q2, self.dq1, self.dq2
        for _ in range(SUBSTEPS):
            c2, s2 = math.cos(q2), math.sin(q2)
            m11 = I1 + I2 + M1 * LC1 * LC1 + M2 * (L1 * L1 + LC2 * LC2 + 2.0 * L1 * LC2 * c2)
            m12 = I2 + M2 * (LC2 * LC2 + L1 * LC2 * c2)
            m22 = I2 + M2 * LC2 * LC2
            h = M2 * L1 * LC2 * s2
            cor1 = -h * (2.0 * dq1 * dq2 + dq2 * dq2)
            cor2 = h * dq1 * dq1
            g1, g2 = _gravity(q1, q2)
            r1 = t1 - cor1 - g1 - B * dq1
            r2 = t2 - cor2 - g2 - B * dq2
            det = m11 * m22 - m12 * m12
            ddq1 = (m22 * r1 - m12 * r2) / det
            ddq2 = (m11 * r2 - m12 * r1) / det
            dq1 = min(QD_MAX, max(-QD_MAX, dq1 + DT * ddq1))
            dq2 = min(QD_MAX, max(-QD_MAX, dq2 + DT * ddq2))
            q1 += DT * dq1
            q2 += DT * dq2
        # keep the stored angles bounded (the observation only shows cos/sin)
        self.q1 = (q1 + math.pi) % (2.0 * math.pi) - math.pi
        self.q2 = (q2 + math.pi) % (2.0 * math.pi) - math.pi
        self.dq1, self.dq2 = dq1, dq2
        self.t += 1
        obs, info = self._obs_info()
        dist = float(np.linalg.norm(info["position"] - self.target))
        reward = -dist - 0.05 * float(a @ a)
        info["distance"] = dist
        return obs, reward, False, False, info

    # -- oracle label source ---------------------------------------------------------------------------
    def waypoint_controller(self, obs, info, kp=60.0, kd=8.0):
        q1, q2, dq1, dq2 = self.q1, self.q2, self.dq1, self.dq2
        s1, c1 = math.sin(q1), math.cos(q1)
        s12, c12 = math.sin(q1 + q2), math.cos(q1 + q2)
        j11, j12 = -L1 * s1 - L2 * s12, -L2 * s12
        j21, j22 = L1 * c1 + L2 * c12, L2 * c12
        vx, vy = j11 * dq1 + j12 * dq2, j21 * dq1 + j22 * dq2
        tip = _fingertip(q1, q2)
        wp = info["waypoint"]
        fx = kp * (wp[0] - tip[0]) - kd * vx
        fy = kp * (wp[1] - tip[1]) - kd * vy
        g1, g2 = _gravity(q1, q2)
        tau1 = g1 + B * dq1 + j11 * fx + j21 * fy
        tau2 = g2 + B * dq2 + j12 * fx + j22 * fy
        return np.clip(np.array([tau1 / TAU_MAX[0], tau2 / TAU_MAX[1]]), -1.0, 1.0).astype(np.float32)


# reward_threshold: check-env's suggestion (-80.07 +- 2.80: 90% of the way from zero action to the controller)
gym.register("GravArm-v0", entry_point=GravArm, max_episode_steps=MAX_STEPS, reward_threshold=-80.0)
