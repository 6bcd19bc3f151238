"""Ball on a tilting plate (2-D), for shaped-es.

Plate tilts alpha = (alpha_x, alpha_y) in [-0.25, 0.25] rad, driven by rate: alpha' = 1.5 * a, a in [-1, 1]^2.
Ball: acc = (5/7) * 9.81 * sin(alpha) - 0.3 * v per axis; dt 0.02, semi-implicit Euler (v then p).
Plate 1 x 1: |p_i| > 0.5 ends the episode with reward -10.
Start: ball at rest in [-0.35, 0.35]^2, plate level; goal in [-0.35, 0.35]^2 at least 0.2 from the start.
Waypoints every 0.08 on the start-goal line (the goal last), consumed within 0.04 of the ball.
Reward: 10 * (decrease of the distance to the current waypoint) each step, + 0.2 per step while the ball
is within 0.04 of the goal with speed < 0.05. 250 steps.
Observation (8): ball position, ball velocity, tilt angles, goal - ball position.
info: "position" = ball position, "waypoint" = the current (next unconsumed) waypoint, the goal once all are.
"""
import gymnasium as gym
import numpy as np

DT = 0.02
G_EFF = 5.0 / 7.0 * 9.81
FRICTION = 0.3
RATE = 1.5
TILT_MAX = 0.25
HALF = 0.5
SPACING = 0.08
REACH = 0.04


class Plate(gym.Env):
    metadata = {"render_modes": []}

    observation_space = gym.spaces.Box(-np.inf, np.inf, (8,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)

    def __init__(self, render_mode=None):
        self.render_mode = render_mode

    # -- helpers ---------------------------------------------------------
    def _waypoints(self):
        d = self.goal - self.start
        dist = float(np.linalg.norm(d))
        u = d / dist
        n = int(np.floor(dist / SPACING))
        pts = [self.start + k * SPACING * u for k in range(1, n + 1)]
        if not pts or np.linalg.norm(pts[-1] - self.goal) > 1e-9:
            pts.append(self.goal.copy())
        return np.array(pts)

    def _consume(self):
        while self.wp_idx < len(self.wps) - 1 and np.linalg.norm(self.wps[self.wp_idx] - self.pos) <= REACH:
            self.wp_idx += 1
        if self.wp_idx == len(self.wps) - 1 and np.linalg.norm(self.wps[-1] - self.pos) <= REACH:
            self.goal_reached = True  # keep reporting the goal

    def _obs_info(self):
        obs = np.concatenate([self.pos, self.vel, self.alpha, self.goal - self.pos]).astype(np.float32)
        info = {"position": self.pos.copy(), "waypoint": self.wps[self.wp_idx].copy()}
        return obs, info

    # -- gym API -----------------------------------------------------------
    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        rng = self.np_random
        self.start = rng.uniform(-0.35, 0.35, 2)
        while True:
            self.goal = rng.uniform(-0.35, 0.35, 2)
            if np.linalg.norm(self.goal - self.start) >= 0.2:
                break
        self.pos = self.start.copy()
        self.vel = np.zeros(2)
        self.alpha = np.zeros(2)
        self.wps = self._waypoints()
        self.wp_idx = 0
        self.goal_reached = False
        self._consume()
        return self._obs_info()

    def step(self, action):
        a = np.clip(np.asarray(action, dtype=np.float64).reshape(2), -1.0, 1.0)
        wp = self.wps[self.wp_idx]
        d0 = float(np.linalg.norm(wp - self.pos))
        self.alpha = np.clip(self.alpha + DT * RATE * a, -TILT_MAX, TILT_MAX)
        acc = G_EFF * np.sin(self.alpha) - FRICTION * self.vel
        self.vel = self.vel + DT * acc
        self.pos = self.pos + DT * self.vel
        if np.any(np.abs(self.pos) > HALF):
            obs, info = self._obs_info()
            return obs, -10.0, True, False, info
        d1 = float(np.linalg.norm(wp - self.pos))
        reward = 10.0 * (d0 - d1)
        self._consume()
        if np.linalg.norm(self.goal - self.pos) <= REACH and np.linalg.norm(self.vel) < 0.05:
            reward += 0.2
        obs, info = self._obs_info()
        return obs, float(reward), False, False, info

    # -- scripted controller: cascaded PD toward the goal ----------------------
    KP, KD, KA = 10.0, 4.5, 10.0

    def waypoint_controller(self, obs, info):
        p, v, al = obs[0:2].astype(np.float64), obs[2:4].astype(np.float64), obs[4:6].astype(np.float64)
        err = obs[6:8].astype(np.float64)  # goal - p
        acc_des = self.KP * err - self.KD * v
        s = np.clip((acc_des + FRICTION * v) / G_EFF, -np.sin(TILT_MAX), np.sin(TILT_MAX))
        alpha_des = np.arcsin(s)
        return np.clip(self.KA * (alpha_des - al) / RATE, -1.0, 1.0).astype(np.float32)


gym.register("Plate-v0", entry_point=Plate, max_episode_steps=250, reward_threshold=37.3)  # check-env: 37.32 +- 0.48
