"""A planar differential-drive robot with first-order actuator lag, following waypoints to a goal.

Action a = (v_cmd, w_cmd) in [-1, 1]^2. The actual speeds lag the commands:
    v += 0.15 * (V_MAX * v_cmd - v);  w += 0.15 * (W_MAX * w_cmd - w)
then x += v dt cos th, y += v dt sin th, th += w dt  (dt 0.1, V_MAX 1 m/s, W_MAX 2 rad/s).

Episode: random start pose (x, y in [-2, 2], th uniform), goal 2-4 m away in a random direction,
waypoints every 0.4 m on the straight start-goal line (the goal is the last one). A waypoint is consumed
when the robot is within 0.2 m of it, or (README's "reached or passed" advice) when the robot's
projection on the start-goal line has passed it; the goal itself only counts within 0.2 m.
150 steps; the episode ends (terminated) when the goal is reached.

Observation (10): x, y, cos th, sin th, v / V_MAX, w / W_MAX, waypoint - position in the robot's frame
(2), goal - position in the robot's frame (2).

Reward per step: progress toward the current waypoint (its distance before the step minus after, m),
+ WP_BONUS for each waypoint consumed, + GOAL_BONUS when the goal is reached.
"""

import gymnasium as gym
import numpy as np

DT, V_MAX, W_MAX, LAG = 0.1, 1.0, 2.0, 0.15
SPACING, REACH = 0.4, 0.2
WP_BONUS, GOAL_BONUS = 0.25, 5.0
MAX_STEPS = 150


class LaggedDiffDrive(gym.Env):
    metadata = {"render_modes": []}
    observation_space = gym.spaces.Box(-50.0, 50.0, (10,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)

    def _rot(self, d):
        c, s = np.cos(self.th), np.sin(self.th)
        return np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1]])

    def _obs_info(self):
        p = np.array([self.x, self.y])
        wp = self.wps[self.k]
        obs = np.concatenate([
            p, [np.cos(self.th), np.sin(self.th), self.v / V_MAX, self.w / W_MAX],
            self._rot(wp - p), self._rot(self.goal - p),
        ]).astype(np.float32)
        info = {"position": p.copy(), "waypoint": wp.copy(), "waypoints_left": len(self.wps) - self.k}
        return obs, info

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        r = self.np_random
        self.x, self.y = r.uniform(-2.0, 2.0, 2)
        self.th = r.uniform(-np.pi, np.pi)
        self.v = self.w = 0.0
        dist, ang = r.uniform(2.0, 4.0), r.uniform(-np.pi, np.pi)
        self.start = np.array([self.x, self.y])
        self.dir = np.array([np.cos(ang), np.sin(ang)])
        self.goal = self.start + dist * self.dir
        n = int(np.ceil(dist / SPACING))
        s = np.minimum(SPACING * np.arange(1, n + 1), dist)
        self.wps = self.start + s[:, None] * self.dir  # last one is the goal
        self.s = s
        self.k = 0
        return self._obs_info()

    def _advance(self):
        """Consume reached or passed waypoints; returns (number consumed, goal reached)."""
        p = np.array([self.x, self.y])
        proj = float((p - self.start) @ self.dir)
        n, last = 0, len(self.wps) - 1
        while self.k < last and (proj >= self.s[self.k] or np.linalg.norm(self.wps[self.k] - p) <= REACH):
            self.k += 1
            n += 1
        goal = np.linalg.norm(self.goal - p) <= REACH
        return n, goal

    def step(self, action):
        a = np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0)
        wp = self.wps[self.k]
        d0 = np.hypot(wp[0] - self.x, wp[1] - self.y)
        self.v += LAG * (V_MAX * a[0] - self.v)
        self.w += LAG * (W_MAX * a[1] - self.w)
        self.x += self.v * DT * np.cos(self.th)
        self.y += self.v * DT * np.sin(self.th)
        self.th = (self.th + self.w * DT + np.pi) % (2 * np.pi) - np.pi
        d1 = np.hypot(wp[0] - self.x, wp[1] - self.y)
        reward = d0 - d1
        n, goal = self._advance()
        reward += WP_BONUS * n
        if goal:
            reward += WP_BONUS + GOAL_BONUS
        obs, info = self._obs_info()
        info["is_success"] = bool(goal)
        return obs, float(reward), bool(goal), False, info

    def waypoint_controller(self, obs, info):
        """Scripted oracle: aim at the waypoint, slow down while the heading error is large."""
        d = self._rot(np.asarray(info["waypoint"]) - np.asarray(info["position"]))
        err = np.arctan2(d[1], d[0])
        w_cmd = np.clip(1.5 * err, -1.0, 1.0)
        v_cmd = np.clip(np.cos(err), 0.0, 1.0) ** 2
        return np.array([v_cmd, w_cmd], dtype=np.float32)


# Threshold 8.0: the scripted controller scores 9.41 (reaches the goal on 200/200 episodes); an episode
# that ends just short of the goal scores at most ~4.2, so a 15-episode mean of 8.0 needs the goal on at
# least ~73% of episodes even if every miss is a near miss (~85% if misses stall): "most episodes".
gym.register("Lagged-v0", entry_point=LaggedDiffDrive, max_episode_steps=MAX_STEPS, reward_threshold=8.0)
