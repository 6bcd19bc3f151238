"""Two stochastic bodies for shaped-es, written from its README's env contract.

NoisyPoint-v0: a 2-D point, velocity control (pos += dt * v, a in [-1, 1]^2, dt 0.05) with
    actuator noise: v = g * a + n + wind, g ~ N(1, 0.3) per step per axis (multiplicative gain),
    n ~ N(0, 0.02) per step per axis (additive), wind an Ornstein-Uhlenbeck velocity
    (time constant 2 s = 40 steps, stationary std 0.3 of the max speed 1.0).
    Random start and goal (in [-1, 1]^2, 0.5-2.0 apart), spatial waypoints every 0.1 on the
    start-goal line (consumed when within 0.05 or passed along the line), dense progress reward
    10 * (d_prev - d) / d_0 (a full reach is ~10), the episode ends within 0.05 of the goal, 100 steps.
    Observation (6): position, goal - position, next waypoint - position, each built from one noisy
    position estimate (N(0, 0.01) per axis per step); info["position"] is the true position.

SlipDrive-v0: a differential-drive robot commanded by its two wheel speeds (left, right) in [-1, 1]
    (m/s at the wheel rim), track width 0.4 m, dt 0.05. Each step each wheel's effective speed is the
    command times U(0.5, 1.0) (random slip), and the heading gets N(0, 0.03) rad of noise per step.
    x += v dt cos(th); y += v dt sin(th); th += w dt (explicit Euler), v = (l + r) / 2, w = (r - l) / 0.4.
    Random start, heading and goal, waypoints every 0.1 on the start-goal line as above, the same
    progress reward, ends within 0.1 of the goal, 150 steps.
    Observation (8): x, y, cos th, sin th, goal offset in the body frame (2), next waypoint offset in
    the body frame (2).

All randomness comes from self.np_random, seeded by reset(seed=...).
Both carry a scripted waypoint_controller (the oracle label source and the threshold's reference).
"""

import math

import gymnasium as gym
import numpy as np

SPACING = 0.1
REACH = 0.05


class _WaypointLine:
    """Waypoints every SPACING on the start-goal line; consumed when passed or within REACH."""

    def _init_line(self, start, goal):
        self.start = np.array(start, dtype=np.float64)
        self.goal = np.array(goal, dtype=np.float64)
        d = self.goal - self.start
        self.length = float(math.hypot(d[0], d[1]))
        self.u = d / self.length
        self.n_wp = max(1, int(math.ceil(self.length / SPACING)))
        self.k = 1  # index of the next waypoint (1..n_wp; n_wp is the goal)
        self.d0 = self.length

    def _wp(self, k):
        if k >= self.n_wp:
            return self.goal.copy()
        return self.start + (k * SPACING) * self.u

    def _advance(self, pos):
        s = float((pos - self.start) @ self.u)
        while self.k < self.n_wp and s >= self.k * SPACING:
            self.k += 1
        while self.k < self.n_wp:
            w = self._wp(self.k)
            if math.hypot(pos[0] - w[0], pos[1] - w[1]) < REACH:
                self.k += 1
            else:
                break

    def _sample_start_goal(self, rng, lo=0.5, hi=2.0):
        while True:
            s = rng.uniform(-1.0, 1.0, 2)
            g = rng.uniform(-1.0, 1.0, 2)
            if lo <= float(np.linalg.norm(g - s)) <= hi:
                return s, g


class NoisyPoint(_WaypointLine, gym.Env):
    metadata = {"render_modes": []}
    observation_space = gym.spaces.Box(-10.0, 10.0, (6,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)
    position_period = None  # nothing wraps

    dt = 0.05
    gain_std = 0.3
    add_std = 0.02
    wind_tau = 2.0  # seconds
    wind_std = 0.3  # stationary std, in units of the max speed (1.0)
    obs_std = 0.01
    goal_radius = 0.05

    def __init__(self, noise_scale=1.0):
        self.noise_scale = float(noise_scale)

    def _obs_info(self):
        p_obs = self.pos + self.noise_scale * self.obs_std * self.np_random.normal(size=2)
        w = self._wp(self.k)
        obs = np.concatenate([p_obs, self.goal - p_obs, w - p_obs]).astype(np.float32)
        self._last_obs = obs
        info = {"position": self.pos.copy(), "waypoint": w}
        return obs, info

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        s, g = self._sample_start_goal(self.np_random)
        self._init_line(s, g)
        self.pos = s.copy()
        self.wind = self.noise_scale * self.wind_std * self.np_random.normal(size=2)
        self.dist = self.length
        return self._obs_info()

    def step(self, action):
        a = np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0)
        rng = self.np_random
        ns = self.noise_scale
        gain = 1.0 + ns * self.gain_std * rng.normal(size=2)
        add = ns * self.add_std * rng.normal(size=2)
        # Ornstein-Uhlenbeck wind: dw = -w/tau dt + sigma sqrt(2/tau) dW
        th = self.dt / self.wind_tau
        self.wind = self.wind * (1.0 - th) + ns * self.wind_std * math.sqrt(2.0 * th) * rng.normal(size=2)
        vel = gain * a + add + self.wind
        self.pos = np.clip(self.pos + self.dt * vel, -3.0, 3.0)
        self._advance(self.pos)
        d = float(math.hypot(self.goal[0] - self.pos[0], self.goal[1] - self.pos[1]))
        reward = 10.0 * (self.dist - d) / self.d0
        self.dist = d
        terminated = d < self.goal_radius
        obs, info = self._obs_info()
        return obs, reward, terminated, False, info

    def waypoint_controller(self, obs, info):
        """Full speed toward the goal as observed (the waypoints lie on that line), saturating."""
        off = np.asarray(obs[2:4], dtype=np.float64)
        n = float(np.linalg.norm(off))
        a = off / max(n, 0.05)
        return np.clip(a, -1.0, 1.0).astype(np.float32)


class SlipDrive(_WaypointLine, gym.Env):
    metadata = {"render_modes": []}
    observation_space = gym.spaces.Box(-10.0, 10.0, (8,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)  # left, right wheel speed
    position_period = None

    dt = 0.05
    track = 0.4
    slip_lo = 0.5
    heading_std = 0.03
    goal_radius = 0.1

    def __init__(self, slip_lo=0.5, heading_std=0.03, heading_first=False):
        self.slip_lo = float(slip_lo)
        self.heading_std = float(heading_std)
        self.heading_first = bool(heading_first)

    def _obs_info(self):
        c, s = math.cos(self.th), math.sin(self.th)
        w = self._wp(self.k)
        g = self.goal - self.pos
        dw = w - self.pos
        body = lambda v: (c * v[0] + s * v[1], -s * v[0] + c * v[1])  # noqa: E731
        obs = np.array([self.pos[0], self.pos[1], c, s, *body(g), *body(dw)], dtype=np.float32)
        info = {"position": self.pos.copy(), "waypoint": w}
        return obs, info

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        s, g = self._sample_start_goal(self.np_random)
        self._init_line(s, g)
        self.pos = s.copy()
        self.th = float(self.np_random.uniform(-math.pi, math.pi))
        self.dist = self.length
        return self._obs_info()

    def step(self, action):
        a = np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0)
        rng = self.np_random
        slip = rng.uniform(self.slip_lo, 1.0, size=2)
        left, right = a[0] * slip[0], a[1] * slip[1]
        v = 0.5 * (left + right)
        w = (right - left) / self.track
        noise = self.heading_std * float(rng.normal())
        if self.heading_first:
            self.th = self.th + self.dt * w + noise
        self.pos = np.clip(
            self.pos + self.dt * v * np.array([math.cos(self.th), math.sin(self.th)]), -3.0, 3.0
        )
        if not self.heading_first:
            self.th = self.th + self.dt * w + noise
        self._advance(self.pos)
        d = float(math.hypot(self.goal[0] - self.pos[0], self.goal[1] - self.pos[1]))
        reward = 10.0 * (self.dist - d) / self.d0
        self.dist = d
        terminated = d < self.goal_radius
        obs, info = self._obs_info()
        return obs, reward, terminated, False, info

    def waypoint_controller(self, obs, info):
        """Turn toward a look-ahead point (the goal as observed, in the body frame), drive when facing it."""
        gx, gy = float(obs[4]), float(obs[5])
        err = math.atan2(gy, gx)
        v = max(0.0, math.cos(err)) * 0.9
        w = float(np.clip(4.0 * err, -4.0, 4.0))  # rad/s
        left = v - 0.5 * self.track * w
        right = v + 0.5 * self.track * w
        m = max(1.0, abs(left), abs(right))
        return np.array([left / m, right / m], dtype=np.float32)


gym.register("NoisyPoint-v0", entry_point=NoisyPoint, max_episode_steps=100, reward_threshold=8.0)
gym.register("SlipDrive-v0", entry_point=SlipDrive, max_episode_steps=150, reward_threshold=8.3)
