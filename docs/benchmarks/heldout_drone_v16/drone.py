"""A planar quadrotor (2-D drone) flying from a random start to a random goal through spatial waypoints.

State: x, z (m), pitch theta (rad, positive tilts the thrust toward +x), vx, vz (m/s), omega (rad/s).
Action: two normalized rotor commands in [-1, 1], rotor i's thrust T_i = (a_i + 1) / 2 * T_MAX with
T_MAX = m g (so a = (0, 0) hovers; thrust-to-weight 2). Rotor 1 sits at -ARM along the body's x axis,
rotor 2 at +ARM.

Dynamics (semi-implicit Euler, dt 0.05 s; velocities first, then positions with the new velocities):
    F = T1 + T2
    vx    += (F sin(theta) / m - DRAG * vx) dt
    vz    += (F cos(theta) / m - g - DRAG * vz) dt
    omega += ((T1 - T2) * ARM / I - ANG_DRAG * omega) dt
    x += vx dt;  z += vz dt;  theta += omega dt

Task: start (at rest, level) and goal drawn uniformly in the box x in [0.3, 3.7], z in [0.5, 2.5]
(a 4 m x 3 m arena), at least 1.5 m apart. Waypoints every 0.35 m on the start-goal line, the goal the
last; a waypoint is consumed when the drone is within 0.2 m of it or its projection on the start-goal
line has passed it. Reward per step: 10 x (previous distance to goal - distance to goal) / initial
distance. Crash (z < 0, |theta| > 1.2, or leaving the arena by more than 1 m): -5 and the episode ends.
Reaching the goal within 0.1 m ends it. 150 steps (7.5 s).

Observation (8): goal - position (dx, dz), sin(theta), cos(theta), vx, vz, omega / 5, z.
"""
from __future__ import annotations

import gymnasium as gym
import numpy as np

G = 9.81
MASS = 1.0
ARM = 0.2
INERTIA = 0.02
T_MAX = MASS * G  # per rotor
DRAG = 0.1
ANG_DRAG = 0.5
DT = 0.05
SPACING = 0.35
REACH = 0.2
GOAL_RADIUS = 0.1
CRASH_PENALTY = -5.0
BOX_LO = np.array([0.3, 0.5])
BOX_HI = np.array([3.7, 2.5])
ARENA_LO = np.array([-1.0, 0.0])
ARENA_HI = np.array([5.0, 4.0])
MAX_STEPS = 150


class Drone(gym.Env):
    metadata = {"render_modes": []}
    observation_space = gym.spaces.Box(-np.inf, np.inf, (8,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)

    # -- helpers -------------------------------------------------------------------------------
    def _pos(self):
        return self.s[:2].copy()

    def _advance_waypoints(self):
        p = self._pos()
        along = float(np.dot(p - self.start, self.u))  # projection on the start-goal line
        while self.k < len(self.wps) - 1:
            w = self.wps[self.k]
            if np.linalg.norm(w - p) < REACH or along >= self.wp_s[self.k]:
                self.k += 1
            else:
                break

    def _obs_info(self):
        x, z, th, vx, vz, om = self.s
        d = self.goal - self.s[:2]
        obs = np.array([d[0], d[1], np.sin(th), np.cos(th), vx, vz, om / 5.0, z], np.float32)
        info = {"position": self._pos(), "waypoint": self.wps[self.k].copy()}
        return obs, info

    # -- gym API -------------------------------------------------------------------------------
    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        rng = self.np_random
        while True:
            start = rng.uniform(BOX_LO, BOX_HI)
            goal = rng.uniform(BOX_LO, BOX_HI)
            if np.linalg.norm(goal - start) >= 1.5:
                break
        self.start, self.goal = start, goal
        self.d0 = float(np.linalg.norm(goal - start))
        self.u = (goal - start) / self.d0
        n = int(np.ceil(self.d0 / SPACING))
        self.wp_s = np.minimum(np.arange(1, n + 1) * SPACING, self.d0)
        self.wp_s[-1] = self.d0
        self.wps = start + self.wp_s[:, None] * self.u
        self.k = 0
        self.s = np.array([start[0], start[1], 0.0, 0.0, 0.0, 0.0])
        self.dist = self.d0
        return self._obs_info()

    def step(self, action):
        a = np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0)
        t1, t2 = (a + 1.0) * 0.5 * T_MAX
        x, z, th, vx, vz, om = self.s
        f = t1 + t2
        vx += (f * np.sin(th) / MASS - DRAG * vx) * DT
        vz += (f * np.cos(th) / MASS - G - DRAG * vz) * DT
        om += ((t1 - t2) * ARM / INERTIA - ANG_DRAG * om) * DT
        x += vx * DT
        z += vz * DT
        th += om * DT
        self.s = np.array([x, z, th, vx, vz, om])
        dist = float(np.linalg.norm(self.goal - self.s[:2]))
        reward = 10.0 * (self.dist - dist) / self.d0
        self.dist = dist
        crashed = (z < 0.0 or abs(th) > 1.2 or np.any(self.s[:2] < ARENA_LO - 1.0)
                   or np.any(self.s[:2] > ARENA_HI))
        terminated = bool(crashed or dist < GOAL_RADIUS)
        if crashed:
            reward += CRASH_PENALTY
        self._advance_waypoints()
        obs, info = self._obs_info()
        info["crashed"] = bool(crashed)
        return obs, float(reward), terminated, False, info

    # -- scripted controller (oracle labels; also the hand controller of measure_threshold.py) --
    def waypoint_controller(self, obs, info, target=None):
        """PD on position -> desired acceleration -> desired tilt and total thrust -> rotor thrusts."""
        x, z, th, vx, vz, om = self.s
        tgt = np.asarray(info["waypoint"] if target is None else target, dtype=np.float64)
        ex, ez = tgt[0] - x, tgt[1] - z
        ax = np.clip(3.0 * ex - 2.5 * vx, -4.0, 4.0)
        az = np.clip(3.0 * ez - 2.5 * vz, -4.0, 4.0)
        th_des = float(np.clip(np.arctan2(ax, G + az), -0.5, 0.5))
        f = MASS * (G + az) / max(np.cos(th), 0.3)
        alpha = 60.0 * (th_des - th) - 12.0 * om  # desired angular acceleration
        diff = alpha * INERTIA / ARM  # T1 - T2
        t1 = np.clip(0.5 * (f + diff), 0.0, T_MAX)
        t2 = np.clip(0.5 * (f - diff), 0.0, T_MAX)
        return (np.array([t1, t2]) / T_MAX * 2.0 - 1.0).astype(np.float32)


# reward_threshold: 0.9 x the hand controller's 9.564 over 100 episodes (measure_threshold.py)
gym.register("Drone-v0", entry_point=Drone, max_episode_steps=MAX_STEPS, reward_threshold=8.61)
