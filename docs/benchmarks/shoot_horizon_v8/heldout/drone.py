"""A planar hovering drone: collective thrust and tilt *rate* (x is third order in the tilt input)."""
import gymnasium as gym
import numpy as np

G, DT, DRAG, SPACING = 1.0, 0.05, 0.3, 0.1


class MyDrone(gym.Env):
    observation_space = gym.spaces.Box(-10.0, 10.0, (7,), np.float32)  # vel(2), tilt, tilt rate?, goal - pos(2), dist
    action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)  # thrust (0 = hover), tilt rate

    def _waypoint(self):
        s = float(np.clip(np.dot(self.pos - self.start, self.u), 0.0, self.L))
        ahead = min(self.L, (np.floor(s / SPACING) + 1.0) * SPACING)
        return self.start + ahead * self.u

    def _obs_info(self):
        d = self.goal - self.pos
        obs = np.array([self.vel[0], self.vel[1], self.theta, self.omega, d[0], d[1],
                        np.linalg.norm(d)], dtype=np.float32)
        return obs, {"position": self.pos.copy(), "waypoint": self._waypoint()}

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.start = np.zeros(2)
        while True:
            self.goal = self.np_random.uniform(-1.0, 1.0, 2)
            if np.linalg.norm(self.goal) > 0.5:
                break
        self.L = float(np.linalg.norm(self.goal))
        self.u = self.goal / self.L
        self.pos, self.vel = self.start.copy(), np.zeros(2)
        self.theta, self.omega = 0.0, 0.0
        return self._obs_info()

    def step(self, action):
        a = np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0)
        thrust = G * (1.0 + a[0])
        self.omega = 2.0 * a[1]
        self.theta = float(np.clip(self.theta + DT * self.omega, -0.6, 0.6))
        acc = np.array([thrust * np.sin(self.theta), thrust * np.cos(self.theta) - G]) - DRAG * self.vel
        prev = np.linalg.norm(self.goal - self.pos)
        self.vel = self.vel + DT * acc
        self.pos = self.pos + DT * self.vel
        dist = np.linalg.norm(self.goal - self.pos)
        reward = 10.0 * (prev - dist) / self.L
        crashed = bool(np.any(np.abs(self.pos) > 3.0))
        if crashed:
            reward -= 5.0
        obs, info = self._obs_info()
        return obs, float(reward), crashed, False, info


gym.register("MyDrone-v0", entry_point=MyDrone, max_episode_steps=100, reward_threshold=8.0)
