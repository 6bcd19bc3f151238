"""A planar hydraulic excavator arm whose bucket tip tracks a timed digging path.

Joints: boom (absolute angle from horizontal), stick and bucket (relative angles); pivot at (0, 1.8) m,
links 5.2, 2.8, 1.3 m, ground at y = 0. Actions in [-1, 1]^3 are valve commands: each joint's angular
velocity follows vmax_i * u_i through a first-order lag (tau 0.3 / 0.25 / 0.2 s); |u| < 0.05 does nothing
(deadband), and with the boom's valve closed the boom sags at 0.03 rad/s (a leaky valve). Joint limits
stop a joint (its velocity zeroed). dt 0.05 s, 200 steps.

Each episode: a random start posture and a random digging path sampled in time: approach a random entry
point just above the ground, a cut below ground (an arc or a flat-bottomed cut), then a lift; each segment
with minimum-jerk timing; the last point is held.

info["position"]: the bucket tip; info["waypoint"]: the path's point for the next time step (timed).
Reward: -0.2 * distance of the tip to the path's point for this step; in the last 20 steps +0.25 while
within 0.25 m (the lift-out finished on the path).
Observation (20): sin/cos of the 3 joint angles, joint velocities / vmax, tip / 5, the offsets to the path
points 1, 6, 11 and 21 steps ahead (/ 2), phase t / T.
"""
import math

import gymnasium as gym
import numpy as np

DT = 0.05
T_STEPS = 200
BASE = (0.0, 1.8)
L1, L2, L3 = 5.2, 2.8, 1.3
VMAX = (0.45, 0.6, 0.9)
TAU = (0.3, 0.25, 0.2)
QLO = (-0.6, -2.7, -2.6)
QHI = (1.0, -0.6, 0.4)
DEADBAND = 0.05
SAG = 0.03
AHEAD = (1, 6, 11, 21)


def fk(q1, q2, q3):
    a12 = q1 + q2
    a123 = a12 + q3
    x = BASE[0] + L1 * math.cos(q1) + L2 * math.cos(a12) + L3 * math.cos(a123)
    y = BASE[1] + L1 * math.sin(q1) + L2 * math.sin(a12) + L3 * math.sin(a123)
    return x, y


def _reach_grid():
    """Occupancy grid (0.1 m) of tip positions reachable with every joint 0.1 rad inside its limits."""
    g = [np.linspace(lo + 0.1, hi - 0.1, 60) for lo, hi in zip(QLO, QHI)]
    Q1, Q2, Q3 = np.meshgrid(*g, indexing="ij")
    X = BASE[0] + L1 * np.cos(Q1) + L2 * np.cos(Q1 + Q2) + L3 * np.cos(Q1 + Q2 + Q3)
    Y = BASE[1] + L1 * np.sin(Q1) + L2 * np.sin(Q1 + Q2) + L3 * np.sin(Q1 + Q2 + Q3)
    grid = np.zeros((160, 160), bool)  # x in [-2, 14), y in [-6, 10)
    ix = np.floor((X.ravel() + 2.0) / 0.1).astype(int)
    iy = np.floor((Y.ravel() + 6.0) / 0.1).astype(int)
    ok = (ix >= 0) & (ix < 160) & (iy >= 0) & (iy < 160)
    grid[ix[ok], iy[ok]] = True
    # erode once: a point counts as reachable only if its neighbours are too (a margin)
    er = grid.copy()
    er[1:-1, 1:-1] = grid[1:-1, 1:-1] & grid[:-2, 1:-1] & grid[2:, 1:-1] & grid[1:-1, :-2] & grid[1:-1, 2:]
    return er


_REACH = _reach_grid()


def _reachable(pts):
    ix = np.floor((pts[:, 0] + 2.0) / 0.1).astype(int)
    iy = np.floor((pts[:, 1] + 6.0) / 0.1).astype(int)
    if (ix < 0).any() or (ix >= 160).any() or (iy < 0).any() or (iy >= 160).any():
        return False
    return bool(_REACH[ix, iy].all())


def _minjerk(tau):
    return tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau)


class Excavator(gym.Env):
    metadata = {"render_modes": []}
    observation_space = gym.spaces.Box(-np.inf, np.inf, (20,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (3,), np.float32)
    position_period = None  # the tip's coordinates never wrap

    def _sample_path(self, p0):
        rng = self.np_random
        for _ in range(100):
            xa = rng.uniform(5.0, 7.5)
            A = np.array([xa, 0.15])
            lc = rng.uniform(1.5, 3.0)
            B = np.array([xa - lc, rng.uniform(-0.3, 0.0)])
            depth = rng.uniform(0.3, 0.7)
            expo = 1.0 if rng.uniform() < 0.5 else 0.35  # arc, or flat-bottomed cut
            C = B + np.array([rng.uniform(-0.8, 0.2), rng.uniform(1.5, 2.5)])
            t_app = rng.uniform(2.5, 3.5)
            t_cut = rng.uniform(3.5, 4.5)
            t_lift = rng.uniform(1.5, 2.2)
            t = np.arange(T_STEPS + 1 + max(AHEAD)) * DT
            pts = np.empty((t.size, 2))
            for k, tk in enumerate(t):
                if tk <= t_app:
                    s = _minjerk(tk / t_app)
                    pts[k] = p0 + s * (A - p0)
                elif tk <= t_app + t_cut:
                    s = _minjerk((tk - t_app) / t_cut)
                    pts[k] = A + s * (B - A)
                    pts[k, 1] -= depth * math.sin(math.pi * s) ** expo
                elif tk <= t_app + t_cut + t_lift:
                    s = _minjerk((tk - t_app - t_cut) / t_lift)
                    pts[k] = B + s * (C - B)
                else:
                    pts[k] = C
            if _reachable(pts):
                return pts
        raise RuntimeError("no reachable digging path in 100 tries")

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        rng = self.np_random
        while True:
            q = [rng.uniform(0.2, 0.8), rng.uniform(-2.2, -1.0), rng.uniform(-2.0, -0.5)]
            if fk(*q)[1] > 0.5:
                break
        self.q = q
        self.qd = [0.0, 0.0, 0.0]
        self.t = 0
        self.path = self._sample_path(np.array(fk(*q)))
        return self._obs(), self._info()

    def _tip(self):
        return fk(*self.q)

    def _info(self):
        x, y = self._tip()
        return {"position": np.array([x, y]), "waypoint": self.path[self.t + 1].copy()}

    def _obs(self):
        q, qd = self.q, self.qd
        x, y = self._tip()
        o = [math.sin(q[0]), math.cos(q[0]), math.sin(q[1]), math.cos(q[1]), math.sin(q[2]), math.cos(q[2]),
             qd[0] / VMAX[0], qd[1] / VMAX[1], qd[2] / VMAX[2], x / 5.0, y / 5.0]
        for a in AHEAD:
            w = self.path[self.t + a]
            o.append((w[0] - x) / 2.0)
            o.append((w[1] - y) / 2.0)
        o.append(self.t / T_STEPS)
        return np.array(o, dtype=np.float32)

    def step(self, action):
        a = np.asarray(action, dtype=np.float64).reshape(3)
        q, qd = self.q, self.qd
        for i in range(3):
            u = float(a[i])
            u = -1.0 if u < -1.0 else (1.0 if u > 1.0 else u)
            if abs(u) < DEADBAND:
                target = -SAG if i == 0 else 0.0
            else:
                target = VMAX[i] * u
            qd[i] += (target - qd[i]) * (DT / TAU[i])
            q[i] += qd[i] * DT
            if q[i] < QLO[i]:
                q[i], qd[i] = QLO[i], 0.0
            elif q[i] > QHI[i]:
                q[i], qd[i] = QHI[i], 0.0
        self.t += 1
        x, y = self._tip()
        w = self.path[self.t]
        dist = math.hypot(x - w[0], y - w[1])
        reward = -0.2 * dist
        if self.t > T_STEPS - 20 and dist < 0.25:
            reward += 0.25
        return self._obs(), reward, False, False, self._info()

    # --- scripted resolved-rate controller: J^+ (feed-forward + K * error), lag and deadband compensated
    def waypoint_controller(self, obs, info):
        q, qd = self.q, self.qd
        x, y = self._tip()
        w = self.path[self.t + 1]
        ff = (self.path[self.t + 2] - self.path[self.t]) / (2 * DT)
        v = ff + 4.0 * (w - np.array([x, y]))
        a1, a12 = q[0], q[0] + q[1]
        a123 = a12 + q[2]
        s1, c1, s12, c12, s123, c123 = (math.sin(a1), math.cos(a1), math.sin(a12), math.cos(a12),
                                        math.sin(a123), math.cos(a123))
        J = np.array([[-L1 * s1 - L2 * s12 - L3 * s123, -L2 * s12 - L3 * s123, -L3 * s123],
                      [L1 * c1 + L2 * c12 + L3 * c123, L2 * c12 + L3 * c123, L3 * c123]])
        W = np.diag([1.0 / VMAX[0] ** 2, 1.0 / VMAX[1] ** 2, 1.0 / VMAX[2] ** 2])  # share by speed
        Jw = J @ W
        Jp = Jw.T @ np.linalg.inv(J @ Jw.T + 1e-3 * np.eye(2))
        qdot = Jp @ v
        # null space: keep every joint near the middle of its range
        mid = np.array([(lo + hi) / 2 for lo, hi in zip(QLO, QHI)])
        span = np.array([hi - lo for lo, hi in zip(QLO, QHI)])
        qn = -0.8 * (np.array(q) - mid) / span
        qdot = qdot + (np.eye(3) - Jp @ J) @ qn
        u = np.empty(3)
        for i in range(3):
            # lead the first-order lag: ask for the velocity that brings qd to qdot within one step
            cmd = qd[i] + (qdot[i] - qd[i]) * min(TAU[i] / DT, 3.0)
            ui = cmd / VMAX[i]
            if i == 0 and abs(ui) < DEADBAND and qdot[0] > -SAG:
                ui = DEADBAND * (1.0 if ui >= 0 else -1.0) if abs(qdot[0]) > 1e-3 else DEADBAND
            elif 0.01 < abs(ui) < DEADBAND:
                ui = math.copysign(DEADBAND, ui)
            u[i] = min(1.0, max(-1.0, ui))
        return u.astype(np.float32)


gym.register("Excavator-v0", entry_point=Excavator, max_episode_steps=T_STEPS, reward_threshold=-4.05)
