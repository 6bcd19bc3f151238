"""MountainCarContinuous-v0's dynamics as a waypoint task (a new user's held-out body for shaped-es).

Dynamics: Gymnasium 1.x ``Continuous_MountainCarEnv`` step for step (power 0.0015, gravity
0.0025 cos(3x), |v| <= 0.07, x in [-1.2, 0.6] with the inelastic left wall, goal x >= 0.45 with v >= 0,
start x ~ U(-0.6, -0.4), v = 0).

Observation (scaled to order 1): ``[x, v / 0.07]``.  Action: force in [-1, 1] (1-D).

Reward (dense, so that an ES can climb it before any episode reaches the flag):
  * progress of the car's *reach*: the x on the right-hand slope at which the car would stop if it coasted
    with its current mechanical energy (E = 0.0025/3 sin(3x) + v^2/2), capped at the flag (0.45).  Paid as
    10 x the increase of the best reach so far (so it cannot be farmed by oscillating; the sum is
    10 x (best reach - start reach), at most ~10);
  * +100 when the flag is reached (the episode then terminates, as in Gymnasium);
  * -0.01 a^2 per step (a tenth of Gymnasium's 0.1 a^2: Gymnasium's penalty makes "do nothing" a strong
    local optimum, which is not what this study is about).

Episode: 200 steps (the pumping controller reaches the flag in 77-86 steps (30 seeds) from every start in
U(-0.6, -0.4), so 200 leaves slack while keeping generations cheap).

Two ids, differing only in ``info["waypoint"]`` (1-D, x):
  * ``McarDemo-v0``: timed waypoints from a demonstration: at reset the scripted energy-pumping controller
    (push in the direction of the velocity) is simulated from the episode's start; ``info["waypoint"]`` is
    the x the demonstration had one step after the current step count (held at its last x after it reached
    the flag).
  * ``McarNaive-v0``: spatial waypoints every 0.1 from the start x straight to the flag (x0+0.1, x0+0.2, ...,
    0.45), each consumed when reached or passed (x >= waypoint).

``waypoint_controller`` (both ids): the pumping controller, a = +1 if v > 0 else -1.
"""
import math

import gymnasium as gym
import numpy as np

MIN_X, MAX_X, MAX_V, GOAL_X, POWER = -1.2, 0.6, 0.07, 0.45, 0.0015
MAX_STEPS = 200
THRESHOLD = 97.6  # check-env: 97.58 +- 0.09, 90% of the way from zero action (0.01) to the pumping controller (108.42)
X_BOTTOM = -math.pi / 6.0  # where gravity is zero: the valley's bottom


def _step(x, v, a):
    """Gymnasium's Continuous_MountainCarEnv.step, on floats."""
    force = min(max(a, -1.0), 1.0)
    v += force * POWER - 0.0025 * math.cos(3 * x)
    v = min(max(v, -MAX_V), MAX_V)
    x += v
    x = min(max(x, MIN_X), MAX_X)
    if x == MIN_X and v < 0:
        v = 0.0
    return x, v


def _pump(v):
    return 1.0 if v > 0 else -1.0


def _reach(x, v):
    """The x on the right slope where the car coasting with this energy stops (capped at the flag)."""
    s = math.sin(3 * x) + 1.5 * v * v / 0.0025  # sin(3 x_stop) = sin(3x) + v^2 / (2 * 0.0025/3)
    if s >= math.sin(3 * GOAL_X):
        return GOAL_X
    # right of the bottom: 3x in [-pi/2, pi/2]
    return math.asin(max(s, -1.0)) / 3.0


class Mcar(gym.Env):
    metadata = {"render_modes": []}
    observation_space = gym.spaces.Box(np.array([MIN_X, -1.0], np.float32), np.array([MAX_X, 1.0], np.float32))
    action_space = gym.spaces.Box(-1.0, 1.0, (1,), np.float32)
    waypoints = "demo"

    def __init__(self, render_mode=None):
        self.render_mode = render_mode

    # -- waypoints -------------------------------------------------------------------------------------
    def _make_schedule(self):
        if self.waypoints == "demo":
            xs, x, v = [self.x], self.x, self.v
            for _ in range(MAX_STEPS + 1):
                if not (x >= GOAL_X and v >= 0):
                    x, v = _step(x, v, _pump(v))
                xs.append(x)
            self.demo = np.array(xs)
        else:
            n = int(math.floor((GOAL_X - self.x) / 0.1 + 1e-9))
            pts = [self.x + 0.1 * (k + 1) for k in range(n)]
            if not pts or pts[-1] < GOAL_X - 1e-9:
                pts.append(GOAL_X)
            self.pts = np.array(pts)
            self.k = 0

    def _waypoint(self):
        if self.waypoints == "demo":
            return self.demo[min(self.t + 1, len(self.demo) - 1)]
        while self.k < len(self.pts) - 1 and self.x >= self.pts[self.k]:  # reached or passed
            self.k += 1
        return self.pts[self.k]

    def _obs_info(self):
        info = {"position": np.array([self.x]), "waypoint": np.array([self._waypoint()])}
        return np.array([self.x, self.v / MAX_V], np.float32), info

    # -- Gymnasium API ---------------------------------------------------------------------------------
    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.x, self.v, self.t = float(self.np_random.uniform(-0.6, -0.4)), 0.0, 0
        self.best = _reach(self.x, self.v)
        self._make_schedule()
        return self._obs_info()

    def step(self, action):
        a = float(np.clip(np.asarray(action, dtype=np.float64).reshape(-1)[0], -1.0, 1.0))
        self.x, self.v = _step(self.x, self.v, a)
        self.t += 1
        terminated = bool(self.x >= GOAL_X and self.v >= 0)
        reach = _reach(self.x, self.v)
        reward = 10.0 * max(0.0, reach - self.best) - 0.01 * a * a
        self.best = max(self.best, reach)
        if terminated:
            reward += 100.0
        obs, info = self._obs_info()
        return obs, reward, terminated, False, info

    def waypoint_controller(self, obs, info):
        """The scripted energy pump: push in the direction of the velocity."""
        return np.array([_pump(float(obs[1]))], np.float32)


class McarDemo(Mcar):
    waypoints = "demo"


class McarNaive(Mcar):
    waypoints = "naive"


gym.register("McarDemo-v0", entry_point=McarDemo, max_episode_steps=MAX_STEPS, reward_threshold=THRESHOLD)
gym.register("McarNaive-v0", entry_point=McarNaive, max_episode_steps=MAX_STEPS, reward_threshold=THRESHOLD)
