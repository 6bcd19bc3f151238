"""The point these edge bodies share: a point at the origin, a goal uniform in [-2, 2]^dim, its waypoint
``spacing`` ahead on the straight line to the goal, velocity control clipped to +-``bound``, reward minus the
distance to the goal (times ``reward_scale``). Each body file changes one thing by overriding a class attribute
or ``velocity`` / ``observe`` / ``waypoint``, and registers its id on import."""
import gymnasium as gym
import numpy as np


class GoalPoint(gym.Env):
    dim, spacing, speed, bound, reward_scale = 2, 0.1, 0.1, 5.0, 1.0
    observation_space = gym.spaces.Box(-5.0, 5.0, (4,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)

    def velocity(self, action) -> np.ndarray:
        return np.clip(action, -1.0, 1.0)

    def waypoint(self) -> np.ndarray:
        d = self.goal - self.pos
        return self.pos + min(1.0, self.spacing / max(float(np.linalg.norm(d)), 1e-9)) * d

    def observe(self):
        return np.concatenate([self.pos, self.goal]).astype(np.float32)

    def _obs_info(self):
        return self.observe(), {"position": self.pos.copy(), "waypoint": self.waypoint()}

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.pos = np.zeros(self.dim)
        self.goal = self.np_random.uniform(-2.0, 2.0, self.dim)
        return self._obs_info()

    def step(self, action):
        self.pos = np.clip(self.pos + self.speed * self.velocity(action), -self.bound, self.bound)
        obs, info = self._obs_info()
        return obs, -self.reward_scale * float(np.linalg.norm(self.goal - self.pos)), False, False, info
