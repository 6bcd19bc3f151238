"""Spacecraft attitude body: three reaction-wheel torques slew roll/pitch/yaw to a random goal.

Second order: torque -> angular acceleration -> body rate -> angle (Euler, small-angle, dt 0.05),
with a little rate damping. The waypoint space is the orientation (roll, pitch, yaw), yaw reported
wrapped to (-pi, pi] as a real attitude sensor would. Waypoints lie on the straight line in angle
space from the start to the goal (yaw the short way round), 0.2 rad apart, consumed when reached or
passed. Reward: progress toward the current waypoint each step, a bonus when the goal is held.
"""

import gymnasium as gym
import numpy as np

DT = 0.05
GAIN = 1.5  # rad/s^2 per unit torque
DAMPING = 0.1  # 1/s
WP_SPACING = 0.2
REACH = 0.1
GOAL_TOL = 0.1
GOAL_RATE_TOL = 0.2
MAX_STEPS = 120


def wrap(a):
    """Wrap to (-pi, pi]."""
    w = np.mod(np.asarray(a, dtype=np.float64) + np.pi, 2 * np.pi) - np.pi
    return np.where(w == -np.pi, np.pi, w)


class Attitude(gym.Env):
    metadata = {"render_modes": []}
    # roll and pitch do not wrap, yaw (reported wrapped) wraps at 2 pi
    position_period = [None, None, 2 * np.pi]

    # obs: roll, pitch, sin yaw, cos yaw, 3 rates, 3 goal errors (yaw's wrapped)
    observation_space = gym.spaces.Box(-10.0, 10.0, (10,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (3,), np.float32)

    def _unwrapped_to_reported(self, p):
        q = np.array(p, dtype=np.float64)
        q[2] = float(wrap(q[2]))
        return q

    def _advance_waypoints(self):
        # advance past every waypoint the body's projection on the start-goal line has passed,
        # then past any within REACH
        line = self.goal_u - self.start
        L2 = float(line @ line)
        if L2 > 1e-12:
            s = float((self.ang - self.start) @ line) / L2
            while self.wp_idx < len(self.waypoints) - 1 and self.wp_s[self.wp_idx] <= s:
                self.wp_idx += 1
        while (self.wp_idx < len(self.waypoints) - 1
               and np.linalg.norm(self.waypoints[self.wp_idx] - self.ang) < REACH):
            self.wp_idx += 1

    def _obs_info(self):
        err = self.goal_u - self.ang  # goal_u and ang both unwrapped: yaw err is the short way
        err[2] = float(wrap(err[2]))
        obs = np.concatenate([
            self.ang[:2], [np.sin(self.ang[2]), np.cos(self.ang[2])], self.rate, err,
        ]).astype(np.float32)
        info = {
            "position": self._unwrapped_to_reported(self.ang),
            "waypoint": self._unwrapped_to_reported(self.waypoints[self.wp_idx]),
            "goal": self._unwrapped_to_reported(self.goal_u),
            "waypoint_index": self.wp_idx,
            "is_success": self.success,
        }
        return obs, info

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        r = self.np_random
        self.ang = np.array([r.uniform(-0.8, 0.8), r.uniform(-0.8, 0.8), r.uniform(-np.pi, np.pi)])
        self.rate = r.uniform(-0.2, 0.2, 3)
        goal = np.array([r.uniform(-0.8, 0.8), r.uniform(-0.8, 0.8), r.uniform(-np.pi, np.pi)])
        # goal in the body's unwrapped frame: yaw the short way round
        self.start = self.ang.copy()
        d = goal - self.start
        d[2] = float(wrap(d[2]))
        self.goal_u = self.start + d
        n = max(1, int(np.ceil(np.linalg.norm(d) / WP_SPACING)))
        self.wp_s = np.arange(1, n + 1) / n
        self.waypoints = [self.start + s * d for s in self.wp_s]
        self.wp_idx = 0
        self.success = False
        self.t = 0
        self._advance_waypoints()
        return self._obs_info()

    def step(self, action):
        a = np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0)
        wp = self.waypoints[self.wp_idx]
        d_before = float(np.linalg.norm(wp - self.ang))
        self.rate = self.rate + DT * (GAIN * a - DAMPING * self.rate)
        self.ang = self.ang + DT * self.rate
        d_after = float(np.linalg.norm(wp - self.ang))
        reward = 10.0 * (d_before - d_after)
        self._advance_waypoints()
        self.t += 1
        terminated = False
        if (np.linalg.norm(self.goal_u - self.ang) < GOAL_TOL
                and np.linalg.norm(self.rate) < GOAL_RATE_TOL):
            reward += 10.0
            terminated = True
            self.success = True
        obs, info = self._obs_info()
        return obs, reward, terminated, False, info

    def waypoint_controller(self, obs, info):
        """PD slew toward the goal (the best controller we have)."""
        err = obs[7:10].astype(np.float64)
        rate = obs[4:7].astype(np.float64)
        return np.clip(1.2 * err - 1.6 * rate, -1.0, 1.0).astype(np.float32)


gym.register("Attitude-v0", entry_point=Attitude, max_episode_steps=MAX_STEPS, reward_threshold=22.4)
