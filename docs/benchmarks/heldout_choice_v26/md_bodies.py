"""Two bodies whose actions are choices (the twenty-ninth session's study; the runs used this code, the docstring was
rewritten after):

- ``GridMD-v0``: a point moved 0.05 a step along each axis by ``MultiDiscrete([3, 3])`` (per axis: 0 stays, 1 +, 2 -);
- ``Thrusters-v0``: a point mass (velocity decays by 0.9 a step) pushed by four on/off thrusters, ``MultiBinary(4)``
  (+x, -x, +y, -y; all off: no force).

Random start and goal in [-1, 1]^2, ``info["waypoint"]`` 0.1 along the line to the goal, reward 10 x the distance
gained each step, 60 / 80 steps; observation: position, goal offset, velocity.
"""
import gymnasium as gym
import numpy as np


class _Base(gym.Env):
    observation_space = gym.spaces.Box(-5, 5, (6,), np.float32)
    STEP = 0.05

    def _info(self):
        d = self.goal - self.pos
        dist = float(np.linalg.norm(d))
        wp = self.pos + d * min(1.0, 0.1 / max(dist, 1e-6))
        return {"position": self.pos.copy(), "waypoint": wp.astype(np.float32)}

    def _obs(self):
        return np.concatenate([self.pos, self.goal - self.pos, self.vel]).astype(np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.pos = self.np_random.uniform(-1, 1, 2).astype(np.float32)
        self.goal = self.np_random.uniform(-1, 1, 2).astype(np.float32)
        self.vel = np.zeros(2, np.float32)
        return self._obs(), self._info()

    def step(self, action):
        before = float(np.linalg.norm(self.goal - self.pos))
        self._move(action)
        after = float(np.linalg.norm(self.goal - self.pos))
        return self._obs(), 10 * (before - after), False, False, self._info()



class GridMD(_Base):
    action_space = gym.spaces.MultiDiscrete([3, 3])
    MOVE = np.array([0.0, 1.0, -1.0], np.float32)

    def _move(self, action):
        a = np.asarray(action)
        self.vel = self.MOVE[a] * self.STEP
        self.pos = np.clip(self.pos + self.vel, -3, 3).astype(np.float32)


class Thrusters(_Base):
    action_space = gym.spaces.MultiBinary(4)  # +x, -x, +y, -y

    def _move(self, action):
        a = np.asarray(action, np.float32)
        force = np.array([a[0] - a[1], a[2] - a[3]], np.float32)
        self.vel = (0.9 * self.vel + 0.01 * force).astype(np.float32)
        self.pos = np.clip(self.pos + self.vel, -3, 3).astype(np.float32)


gym.register("GridMD-v0", entry_point=GridMD, max_episode_steps=60)
gym.register("Thrusters-v0", entry_point=Thrusters, max_episode_steps=80)
