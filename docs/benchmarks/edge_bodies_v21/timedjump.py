"""Timed waypoints on a schedule that jump discontinuously: the schedule heads to A for
t<25, then teleports its waypoint to B (far away). Phase in obs. 50 steps."""
import gymnasium as gym
import numpy as np

T = 50


class TimedJump(gym.Env):
    observation_space = gym.spaces.Box(-10.0, 10.0, (7,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)

    def _sched(self, t):
        # piecewise: a fixed point A until t=25, then B; discontinuous jump
        return self.a.copy() if t < 25 else self.b.copy()

    def _obs_info(self):
        info = {"position": self.pos.copy(), "waypoint": self._sched(self.t + 1)}
        obs = np.concatenate([self.pos, self.a, self.b, [self.t / T]]).astype(np.float32)
        return obs, info

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.t = 0
        self.pos = np.zeros(2)
        self.a = self.np_random.uniform(-2.0, 2.0, 2)
        self.b = -self.a + self.np_random.uniform(-0.5, 0.5, 2)
        return self._obs_info()

    def step(self, action):
        self.pos = np.clip(self.pos + 0.15 * np.clip(action, -1.0, 1.0), -10.0, 10.0)
        self.t += 1
        target = self._sched(self.t)
        obs, info = self._obs_info()
        return obs, -float(np.linalg.norm(target - self.pos)), False, False, info


gym.register("TimedJump-v0", entry_point=TimedJump, max_episode_steps=T)
