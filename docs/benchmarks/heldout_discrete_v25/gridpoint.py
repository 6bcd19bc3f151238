"""A grid-ish point: Discrete(5) actions (stay/up/down/left/right), spatial waypoints to a random goal.

heldout_discrete_v25 copy of the new user's env: unchanged dynamics and reward; added
``waypoint_controller`` (the optimal greedy policy: one 0.1 move along the axis with the larger
remaining offset to the goal, stay once there) and an honest ``reward_threshold``.

Threshold: every path that arrives returns 10 x (start distance) + 1 (the progress reward telescopes),
and the goal (each coordinate round(U(-1.5, 1.5), 1)) is at most 30 moves away, inside the 50-step limit,
so the greedy controller is optimal. Its mean return over reset seeds 0-199 is 12.60 (standard error 0.32;
the exact expectation over the goal distribution 12.49). The threshold is 80% of that: 10.0. (The new
user's 18.0 needs a start distance of 1.7 on average: no policy reaches it.)"""
import gymnasium as gym
import numpy as np

MOVES = np.array([[0, 0], [0, 1], [0, -1], [-1, 0], [1, 0]], dtype=np.float64) * 0.1


class GridPoint(gym.Env):
    metadata = {"render_modes": ["rgb_array"]}
    observation_space = gym.spaces.Box(-3.0, 3.0, (4,), np.float32)
    action_space = gym.spaces.Discrete(5)

    def __init__(self, render_mode=None):
        self.render_mode = render_mode

    def _obs_info(self):
        d = self.goal - self.pos
        n = float(np.linalg.norm(d))
        step = min(1.0, 0.1 / max(n, 1e-9))
        info = {"position": self.pos.copy(), "waypoint": self.pos + step * d}
        return np.concatenate([self.pos, self.goal]).astype(np.float32), info

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.pos = np.zeros(2)
        self.goal = np.round(self.np_random.uniform(-1.5, 1.5, 2), 1)
        return self._obs_info()

    def step(self, action):
        a = int(action)
        prev = float(np.linalg.norm(self.goal - self.pos))
        self.pos = np.clip(self.pos + MOVES[a], -3.0, 3.0)
        dist = float(np.linalg.norm(self.goal - self.pos))
        reward = (prev - dist) * 10.0
        done = dist < 0.05
        if done:
            reward += 1.0
        obs, info = self._obs_info()
        return obs, reward, done, False, info

    def waypoint_controller(self, obs, info):
        """The optimal policy: one move along the axis with the larger remaining offset to the goal."""
        d = self.goal - self.pos
        if np.max(np.abs(d)) < 0.05:
            return 0
        if abs(d[0]) >= abs(d[1]):
            return 4 if d[0] > 0 else 3
        return 1 if d[1] > 0 else 2

    def render(self):
        img = np.full((64, 64, 3), 255, np.uint8)
        for p, c in ((self.goal, (0, 200, 0)), (self.pos, (200, 0, 0))):
            i, j = np.clip(((p + 3.0) / 6.0 * 63).astype(int), 0, 63)
            img[max(j - 1, 0):j + 2, max(i - 1, 0):i + 2] = c
        return img


gym.register("GridPoint-v0", entry_point=GridPoint, max_episode_steps=50, reward_threshold=10.0)  # 80% of the optimal mean return 12.60 (seeds 0-199)
