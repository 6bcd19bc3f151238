"""A differential-drive ground robot that senses only relative to itself.

Dynamics (dt = 0.1 s): two wheels driven by acceleration commands in [-1, 1] (scaled to +-ACC m/s^2)
that reach the wheels through a first-order motor lag (time constant TAU); wheel speeds saturate at
+-VMAX; unicycle kinematics with wheel base BASE (x += v dt cos th, y += v dt sin th, th += w dt).

Observation (8-D, robot frame only, no world pose): goal (x, y) in the robot frame / 5, next waypoint
(x, y) in the robot frame / 0.3, left and right wheel speeds / VMAX, the two lagged wheel accelerations
(normalised).  Random start pose, random goal 2-5 m away; spatial waypoints every 0.1 m on the
start-goal line.  Reward: progress toward the goal, scaled so a whole route is worth 10; the episode
ends when the robot is within GOAL_RADIUS of the goal, or after 200 steps.
"""
import gymnasium as gym
import numpy as np

DT = 0.1
ACC = 0.8          # m/s^2 at full command
TAU = 0.5          # s, motor lag on the acceleration
VMAX = 0.5         # m/s per wheel
BASE = 0.3         # m, wheel separation
SPACING = 0.1      # m between waypoints
REACH = 0.05       # m, waypoint reach radius
GOAL_RADIUS = 0.1  # m
MAX_STEPS = 200


class MyRobot(gym.Env):
    metadata = {"render_modes": []}

    observation_space = gym.spaces.Box(-5.0, 5.0, (8,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)  # left, right wheel acceleration
    position_period = None  # the position is world (x, y): nothing wraps

    # ---- helpers ---------------------------------------------------------------------------
    def _to_body(self, p):
        d = np.asarray(p, dtype=np.float64) - self.pos
        c, s = np.cos(self.th), np.sin(self.th)
        return np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1]])

    def _advance_waypoints(self):
        # consume every waypoint the robot's projection on the start-goal line has passed,
        # then any within the reach radius
        proj = float(np.dot(self.pos - self.start, self.u))
        n = len(self.wps)
        while self.k < n - 1 and proj >= self.s_wp[self.k]:
            self.k += 1
        while self.k < n - 1 and np.linalg.norm(self.wps[self.k] - self.pos) < REACH:
            self.k += 1

    def _obs_info(self):
        g = self._to_body(self.goal) / 5.0
        w = self._to_body(self.wps[self.k]) / 0.3
        obs = np.concatenate([g, np.clip(w, -4.0, 4.0), self.v / VMAX, self.a]).astype(np.float32)
        info = {"position": self.pos.copy(), "waypoint": self.wps[self.k].copy()}
        return obs, info

    # ---- gym API ---------------------------------------------------------------------------
    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        rng = self.np_random
        self.pos = rng.uniform(-2.0, 2.0, 2)
        self.th = rng.uniform(-np.pi, np.pi)
        dist = rng.uniform(2.0, 5.0)
        ang = rng.uniform(-np.pi, np.pi)
        self.u = np.array([np.cos(ang), np.sin(ang)])
        self.start = self.pos.copy()
        self.goal = self.start + dist * self.u
        n = int(np.ceil(dist / SPACING))
        self.s_wp = np.minimum(np.arange(1, n + 1) * SPACING, dist)
        self.wps = self.start + self.s_wp[:, None] * self.u
        self.k = 0
        self.v = np.zeros(2)   # wheel speeds (left, right)
        self.a = np.zeros(2)   # lagged accelerations (normalised to [-1, 1])
        self.d0 = dist
        self.dist = dist
        self.t = 0
        return self._obs_info()

    def step(self, action):
        cmd = np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0)
        self.a += (DT / TAU) * (cmd - self.a) if TAU > DT else (cmd - self.a)
        self.v = np.clip(self.v + ACC * DT * self.a, -VMAX, VMAX)
        v = 0.5 * (self.v[0] + self.v[1])
        w = (self.v[1] - self.v[0]) / BASE
        self.pos = self.pos + v * DT * np.array([np.cos(self.th), np.sin(self.th)])
        self.th = float(np.angle(np.exp(1j * (self.th + w * DT))))
        self.t += 1
        self._advance_waypoints()
        new_dist = float(np.linalg.norm(self.goal - self.pos))
        reward = 10.0 * (self.dist - new_dist) / (self.d0 - GOAL_RADIUS)
        self.dist = new_dist
        terminated = new_dist < GOAL_RADIUS
        obs, info = self._obs_info()
        return obs, float(reward), bool(terminated), False, info

    # ---- scripted controller (oracle labels, threshold reference) ---------------------------
    def waypoint_controller(self, obs, info):
        """Pursue a point 0.6 m ahead on the start-goal line; wheel-speed targets tracked through
        the acceleration command, with a lead term for the motor lag."""
        proj = float(np.dot(self.pos - self.start, self.u))
        s = min(max(proj, 0.0) + 0.6, self.d0)
        p = self._to_body(self.start + s * self.u)
        bearing = np.arctan2(p[1], p[0])
        dist_goal = float(np.linalg.norm(self.goal - self.pos))
        v_des = VMAX * max(0.0, np.cos(bearing)) ** 2 * min(1.0, dist_goal / 0.4 + 0.3)
        w_des = 1.0 * bearing
        vl = v_des - 0.5 * BASE * w_des
        vr = v_des + 0.5 * BASE * w_des
        m = max(abs(vl), abs(vr), VMAX) / VMAX
        v_tgt = np.array([vl, vr]) / m
        a_des = np.clip((v_tgt - self.v) / (ACC * 0.6), -1.0, 1.0)
        cmd = self.a + (TAU / 0.2) * (a_des - self.a)
        return np.clip(cmd, -1.0, 1.0).astype(np.float32)


gym.register("MyRobot-v0", entry_point=MyRobot, max_episode_steps=MAX_STEPS, reward_threshold=9.06)
