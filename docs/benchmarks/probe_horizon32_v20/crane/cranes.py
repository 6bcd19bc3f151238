"""A 2-D gantry crane: a trolley on a rail carries a load on a hoisted rope; the LOAD must follow waypoints.

Dynamics (vertical x-z plane, dt = 0.05 s, 2 Euler substeps):
  trolley  x'' = 3 u0 - 0.5 x'   (rail clipped to [-2.5, 2.5]);  rope  l' = 0.6 u1  (l clipped to [0.3, 1.6])
  swing    l th'' = -(g sin th + x'' cos th + 2 l' th') - 0.05 l th'   ;  load p = (x + l sin th, -l cos th)
So the load moves only through the swing (trolley acceleration shows in the load a few steps late).

Episode: random trolley x and rope length at rest; random load goal (x in [-1.5, 1.5], z in [-1.4, -0.4])
0.8-2.0 away. Waypoints every 0.1 on the load's start-goal line, consumed when passed or within 0.05.
Reward: 10 * (|p_t - g| - |p_{t+1} - g|) / d0 - 0.01 per step - 0.002 th'^2 (swing). 120 steps.

reward_threshold 7.0: about 0.9 x the anti-sway waypoint controller's mean return (check-env prints it).
"""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np

DT, SUB, G = 0.05, 2, 9.81
SPACING, REACH = 0.1, 0.05


class CraneLoad(gym.Env):
    metadata = {"render_modes": []}
    observation_space = gym.spaces.Box(-np.inf, np.inf, (10,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)  # trolley force, hoist rate

    def _load(self):
        return np.array([self.x + self.l * math.sin(self.th), -self.l * math.cos(self.th)])

    def _load_vel(self):
        s, c = math.sin(self.th), math.cos(self.th)
        return np.array([self.v + self.ld * s + self.l * c * self.thd, -self.ld * c + self.l * s * self.thd])

    def _advance_waypoints(self, p):
        u = self.dir
        proj = float(np.dot(p - self.start, u))
        while self.k < self.n and (self.k + 1) * SPACING <= proj:
            self.k += 1
        while self.k < self.n and np.linalg.norm(self._wp(self.k + 1) - p) < REACH:
            self.k += 1

    def _wp(self, k):
        return self.start + min(k * SPACING, self.d0) * self.dir

    def _obs_info(self):
        p = self._load()
        pv = self._load_vel()
        obs = np.array([self.x / 2.5, self.v, self.l, math.sin(self.th), math.cos(self.th), self.thd,
                        *(self.goal - p), *pv], dtype=np.float32)
        info = {"position": p.copy(), "waypoint": self._wp(min(self.k + 1, self.n))}
        return obs, info

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        r = self.np_random
        self.x, self.v = r.uniform(-1.5, 1.5), 0.0
        self.l, self.ld = r.uniform(0.5, 1.2), 0.0
        self.th, self.thd = 0.0, 0.0
        self.start = self._load()
        while True:
            self.goal = np.array([r.uniform(-1.5, 1.5), r.uniform(-1.4, -0.4)])
            d = float(np.linalg.norm(self.goal - self.start))
            if 0.8 <= d <= 2.0:
                break
        self.d0 = d
        self.dir = (self.goal - self.start) / d
        self.n = int(math.ceil(d / SPACING))
        self.k = 0
        self.t = 0
        return self._obs_info()

    def step(self, action):
        a = np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0)
        p0 = self._load()
        h = DT / SUB
        for _ in range(SUB):
            acc = 3.0 * a[0] - 0.5 * self.v
            self.ld = 0.6 * a[1]
            if (self.l <= 0.3 and self.ld < 0) or (self.l >= 1.6 and self.ld > 0):
                self.ld = 0.0
            thdd = (-(G * math.sin(self.th) + acc * math.cos(self.th) + 2 * self.ld * self.thd) / self.l
                    - 0.05 * self.thd)
            self.v += h * acc
            self.x += h * self.v
            if abs(self.x) > 2.5:
                self.x, self.v = math.copysign(2.5, self.x), 0.0
            self.thd += h * thdd
            self.th += h * self.thd
            self.l = min(max(self.l + h * self.ld, 0.3), 1.6)
        p1 = self._load()
        self._advance_waypoints(p1)
        self.t += 1
        reward = (10.0 * (np.linalg.norm(p0 - self.goal) - np.linalg.norm(p1 - self.goal)) / self.d0
                  - 0.01 - 0.002 * self.thd ** 2)
        obs, info = self._obs_info()
        return obs, float(reward), False, False, info

    def waypoint_controller(self, obs, info):
        """Anti-sway PD: the trolley servoes to put the LOAD at a point a bit past the waypoint, with
        feedback on the swing angle; the hoist servoes the rope to the waypoint's depth."""
        wp = np.asarray(info["waypoint"])
        aim = wp + 0.15 * self.dir if np.linalg.norm(wp - self.goal) > 1e-9 else wp
        # trolley target: under the aim
        ex = aim[0] - self.x
        u0 = 1.2 * ex - 1.0 * self.v + 4.0 * self.th + 0.6 * self.thd
        u1 = 3.0 * (-aim[1] - self.l)
        return np.clip(np.array([u0, u1]), -1.0, 1.0).astype(np.float32)


gym.register("CraneLoad-v0", entry_point=CraneLoad, max_episode_steps=120,
             reward_threshold=7.0)  # ~0.9 x the anti-sway controller's mean return
