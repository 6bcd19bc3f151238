"""The waypoint is the goal from the start (one waypoint only); 2-D point, 50 steps."""
import gymnasium as gym
import numpy as np


class GoalWP(gym.Env):
    observation_space = gym.spaces.Box(-5.0, 5.0, (4,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)

    def _obs_info(self):
        info = {"position": self.pos.copy(), "waypoint": self.goal.copy()}
        return np.concatenate([self.pos, self.goal]).astype(np.float32), info

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.pos = np.zeros(2)
        self.goal = self.np_random.uniform(-2.0, 2.0, 2)
        return self._obs_info()

    def step(self, action):
        self.pos = np.clip(self.pos + 0.1 * np.clip(action, -1.0, 1.0), -5.0, 5.0)
        obs, info = self._obs_info()
        return obs, -float(np.linalg.norm(self.goal - self.pos)), False, False, info


gym.register("GoalWP-v0", entry_point=GoalWP, max_episode_steps=50)
