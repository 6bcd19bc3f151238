"""A 2-D holonomic mobile base (vx, vy, yaw-rate in the body frame) passing waypoints to a goal.

Simulates a slow-ish simulator (5 ms a step) with badly scaled raw sensors: the range-to-goal
sensor reads millimetres (~2000), the rest are order 1. 60-step episodes.
"""
import time

import gymnasium as gym
import numpy as np

DT = 0.1
VMAX = np.array([0.5, 0.5, 1.5])  # vx, vy [m/s], yaw rate [rad/s]
SPACING = 0.2
REACH = 0.1


class MyBase(gym.Env):
    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}
    # obs: goal offset in body frame (2), cos/sin heading (2), last body velocity command (3), range to goal in mm (1)
    observation_space = gym.spaces.Box(-np.inf, np.inf, (8,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (3,), np.float32)

    def __init__(self, render_mode=None, reward_array=False):
        self.render_mode = render_mode
        self.reward_array = reward_array

    def _waypoint(self):
        # advance past every waypoint the projection has passed, or that is within REACH
        d = self.goal - self.start
        L = float(np.linalg.norm(d))
        u = d / L
        s = float(np.dot(self.pos - self.start, u))
        while self.k < len(self.wps) - 1 and (
            self.k * SPACING <= s or np.linalg.norm(self.wps[self.k] - self.pos) < REACH
        ):
            self.k += 1
        return self.wps[self.k].copy()

    def _obs_info(self):
        th = self.theta
        g = self.goal - self.pos
        c, s = np.cos(th), np.sin(th)
        g_body = np.array([c * g[0] + s * g[1], -s * g[0] + c * g[1]])
        dist_mm = 1000.0 * np.linalg.norm(g) + self.np_random.normal(0, 5.0)
        obs = np.concatenate([g_body, [c, s], self.cmd, [dist_mm]]).astype(np.float32)
        info = {"position": self.pos.copy(), "waypoint": self._waypoint()}
        return obs, info

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.start = np.zeros(2)
        self.pos = self.start.copy()
        self.theta = float(self.np_random.uniform(-np.pi, np.pi))
        ang = self.np_random.uniform(-np.pi, np.pi)
        r = self.np_random.uniform(1.5, 2.5)
        self.goal = r * np.array([np.cos(ang), np.sin(ang)])
        L = float(np.linalg.norm(self.goal - self.start))
        n = int(np.ceil(L / SPACING))
        self.wps = [self.start + min(1.0, (i * SPACING) / L) * (self.goal - self.start) for i in range(1, n + 1)]
        self.k = 0
        self.cmd = np.zeros(3)
        self.t = 0
        return self._obs_info()

    def step(self, action):
        time.sleep(0.005)  # the simulator's cost
        a = np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0)
        self.cmd = a * VMAX
        c, s = np.cos(self.theta), np.sin(self.theta)
        vx, vy, wz = self.cmd
        before = float(np.linalg.norm(self.goal - self.pos))
        self.pos = self.pos + DT * np.array([c * vx - s * vy, s * vx + c * vy])
        self.theta = float((self.theta + DT * wz + np.pi) % (2 * np.pi) - np.pi)
        after = float(np.linalg.norm(self.goal - self.pos))
        reward = before - after  # progress toward the goal, metres
        terminated = after < REACH
        if terminated:
            reward += 1.0
        obs, info = self._obs_info()
        if self.reward_array:
            reward = np.array([reward], dtype=np.float32)
        return obs, reward, terminated, False, info

    def render(self):
        img = np.full((128, 128, 3), 255, np.uint8)
        def px(p):
            return np.clip(((np.asarray(p) + 3.0) / 6.0 * 127).astype(int), 0, 127)
        for w in self.wps:
            x, y = px(w); img[127 - y, x] = (0, 0, 255)
        x, y = px(self.goal); img[max(0, 125 - y):130 - y, max(0, x - 2):x + 3] = (0, 200, 0)
        x, y = px(self.pos); img[max(0, 125 - y):130 - y, max(0, x - 2):x + 3] = (255, 0, 0)
        return img


gym.register("MyBase-v0", entry_point=MyBase, max_episode_steps=60)
gym.register("MyBaseArr-v0", entry_point=MyBase, max_episode_steps=60, kwargs={"reward_array": True})
