"""Space tug: a 2-D point mass in free space with weak thrusters and no friction.

State: position p, velocity v. Action: 2-D thrust in [-1, 1]^2 (0 = thrusters off, coast).
    v += dt * 0.8 * a  (dt = 0.05), |v| clipped at 1.5;  p += dt * v
Random start (p uniform in a 4x4 m box, initial velocity up to 0.3 m/s in a random direction) and
random goal (same box, at least 1 m away) per episode. Spatial waypoints every 0.4 m on the start-goal
line (the last one is the goal), consumed when reached (within 0.15 m) or passed (the projection of p on
the line beyond the waypoint's). Observation: p, v, and the vector from p to the next waypoint (world
frame). Reward: 10 x progress toward the current waypoint each step, +5 once when the goal is reached
within 0.2 m (the episode then terminates). 150 steps.
"""
import gymnasium as gym
import numpy as np

DT = 0.05
ACCEL = 0.8
VMAX = 1.5
SPACING = 0.4
REACH = 0.15
GOAL_RADIUS = 0.2
HORIZON = 150


class Tug(gym.Env):
    metadata = {"render_modes": []}

    observation_space = gym.spaces.Box(-np.inf, np.inf, (6,), np.float32)  # p, v, w - p
    action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)  # thrust

    position_period = None  # nothing wraps

    def __init__(self, render_mode=None):
        self.render_mode = render_mode

    # ---------------------------------------------------------------- helpers
    def _obs_info(self):
        w = self.waypoints[self.k]
        obs = np.concatenate([self.p, self.v, w - self.p]).astype(np.float32)
        info = {"position": self.p.copy(), "waypoint": w.copy()}
        return obs, info

    def _advance(self):
        """Consume waypoints reached (within REACH) or passed (projection beyond them); never the goal."""
        last = len(self.waypoints) - 1
        s = float(np.dot(self.p - self.start, self.u))  # arc length of p's projection on the line
        while self.k < last:
            w = self.waypoints[self.k]
            if np.linalg.norm(w - self.p) <= REACH or s >= self.s_wp[self.k]:
                self.k += 1
            else:
                break

    # ---------------------------------------------------------------- gym API
    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        rng = self.np_random
        self.p = rng.uniform(-2.0, 2.0, 2)
        while True:
            self.goal = rng.uniform(-2.0, 2.0, 2)
            if np.linalg.norm(self.goal - self.p) >= 1.0:
                break
        ang = rng.uniform(-np.pi, np.pi)
        self.v = rng.uniform(0.0, 0.3) * np.array([np.cos(ang), np.sin(ang)])
        self.start = self.p.copy()
        dist = float(np.linalg.norm(self.goal - self.start))
        self.u = (self.goal - self.start) / dist
        n = int(np.ceil(dist / SPACING))
        self.s_wp = np.array([min(SPACING * (i + 1), dist) for i in range(n)])
        self.waypoints = [self.start + s * self.u for s in self.s_wp]
        self.waypoints[-1] = self.goal.copy()
        self.k = 0
        self.t = 0
        self._advance()
        return self._obs_info()

    def step(self, action):
        a = np.clip(np.asarray(action, dtype=np.float64).reshape(2), -1.0, 1.0)
        w = self.waypoints[self.k]
        d_old = float(np.linalg.norm(w - self.p))
        self.v = self.v + DT * ACCEL * a
        speed = float(np.linalg.norm(self.v))
        if speed > VMAX:
            self.v = self.v * (VMAX / speed)
        self.p = self.p + DT * self.v
        d_new = float(np.linalg.norm(w - self.p))
        reward = 10.0 * (d_old - d_new)
        self.t += 1
        terminated = False
        if np.linalg.norm(self.goal - self.p) <= GOAL_RADIUS:
            reward += 5.0
            terminated = True
            self.k = len(self.waypoints) - 1
        else:
            self._advance()
        obs, info = self._obs_info()
        return obs, reward, terminated, False, info

    # ---------------------------------------------------------------- oracle
    def waypoint_controller(self, obs, info, kp=6.0, kd=3.0):
        """PD law toward the next waypoint with velocity damping."""
        obs = np.asarray(obs, dtype=np.float64)
        e = obs[4:6]  # w - p
        v = obs[2:4]
        return np.clip(kp * e - kd * v, -1.0, 1.0).astype(np.float32)


gym.register("Tug-v0", entry_point=Tug, max_episode_steps=HORIZON, reward_threshold=23.45)  # check-env: 23.45 +- 1.88
