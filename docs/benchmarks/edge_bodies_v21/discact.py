"""2-D point with a Discrete(5) action (stay, +x, -x, +y, -y); waypoint contract. 50 steps."""
import gymnasium as gym
import numpy as np

MOVES = np.array([[0, 0], [1, 0], [-1, 0], [0, 1], [0, -1]], dtype=np.float64)


class DiscAct(gym.Env):
    observation_space = gym.spaces.Box(-5.0, 5.0, (4,), np.float32)
    action_space = gym.spaces.Discrete(5)

    def _obs_info(self):
        d = self.goal - self.pos
        step = min(1.0, 0.1 / max(float(np.linalg.norm(d)), 1e-9))
        info = {"position": self.pos.copy(), "waypoint": self.pos + step * d}
        return np.concatenate([self.pos, self.goal]).astype(np.float32), info

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.pos = np.zeros(2)
        self.goal = self.np_random.uniform(-2.0, 2.0, 2)
        return self._obs_info()

    def step(self, action):
        self.pos = np.clip(self.pos + 0.1 * MOVES[int(action)], -5.0, 5.0)
        obs, info = self._obs_info()
        return obs, -float(np.linalg.norm(self.goal - self.pos)), False, False, info


gym.register("DiscAct-v0", entry_point=DiscAct, max_episode_steps=50)
