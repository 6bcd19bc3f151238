"""A rear-wheel-steered forklift on a plane, driven to a goal through 1 m waypoints.

Kinematic bicycle model whose steered wheel is at the REAR. The reference point is the
front axle (where the forks are): it moves along the body heading at speed v*cos(delta),
while the heading turns at -v*sin(delta)/L (steering the rear wheel left swings the rear
out to the left, so the front turns right: opposite to the steering).

action = [speed command in [-1, 1] m/s (reverse allowed), rear steering angle in [-0.6, 0.6] rad]
obs    = [x/5, y/5, cos(th), sin(th), wx/5, wy/5]  (front axle position, heading, next waypoint)
info   = {"position": front axle (x, y), "waypoint": next waypoint (x, y)}
"""
import gymnasium as gym
import numpy as np

DT = 0.1
WHEELBASE = 1.2
ARENA = 5.0  # starts and goals in [-5, 5]^2
SPACING = 1.0
REACH = 0.3  # waypoint / goal reach radius
GOAL_BONUS = 10.0
MAX_STEPS = 150
POS_LIMIT = 8.0


class Forklift(gym.Env):
    metadata = {"render_modes": []}
    position_period = None  # nothing wraps: the position is (x, y)

    observation_space = gym.spaces.Box(-2.0, 2.0, (6,), np.float32)
    action_space = gym.spaces.Box(
        np.array([-1.0, -0.6], np.float32), np.array([1.0, 0.6], np.float32), dtype=np.float32
    )

    def _obs_info(self):
        w = self.waypoints[self.k]
        obs = np.array(
            [self.pos[0] / ARENA, self.pos[1] / ARENA, np.cos(self.th), np.sin(self.th),
             w[0] / ARENA, w[1] / ARENA],
            np.float32,
        )
        info = {"position": self.pos.copy(), "waypoint": w.copy()}
        return obs, info

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        rng = self.np_random
        self.pos = rng.uniform(-ARENA, ARENA, 2)
        while True:
            goal = rng.uniform(-ARENA, ARENA, 2)
            if 3.0 <= np.linalg.norm(goal - self.pos) <= 8.0:
                break
        self.th = float(rng.uniform(-np.pi, np.pi))
        self.start = self.pos.copy()
        self.goal = goal
        d = goal - self.start
        length = float(np.linalg.norm(d))
        self.dir = d / length
        self.length = length
        n = int(np.ceil(length / SPACING))
        # waypoints every ~1 m on the start-goal line, the last one the goal itself
        self.waypoints = [self.start + d * (i / n) for i in range(1, n + 1)]
        self.k = 0
        return self._obs_info()

    def _advance(self):
        """Consume waypoints reached or passed (projection on the start-goal line), never the goal."""
        last = len(self.waypoints) - 1
        s = float(np.dot(self.pos - self.start, self.dir))
        while self.k < last:
            s_w = float(np.dot(self.waypoints[self.k] - self.start, self.dir))
            if s >= s_w or np.linalg.norm(self.waypoints[self.k] - self.pos) < REACH:
                self.k += 1
            else:
                break

    def step(self, action):
        a = np.asarray(action, np.float64).reshape(-1)
        v = float(np.clip(a[0], -1.0, 1.0))
        delta = float(np.clip(a[1], -0.6, 0.6))
        w_old = self.waypoints[self.k]
        d_old = float(np.linalg.norm(w_old - self.pos))
        # front-axle reference point moves along the heading; rear steering turns the body
        self.pos = self.pos + DT * v * np.cos(delta) * np.array([np.cos(self.th), np.sin(self.th)])
        self.pos = np.clip(self.pos, -POS_LIMIT, POS_LIMIT)
        self.th = float(np.arctan2(np.sin(self.th - DT * v * np.sin(delta) / WHEELBASE),
                                   np.cos(self.th - DT * v * np.sin(delta) / WHEELBASE)))
        reward = d_old - float(np.linalg.norm(w_old - self.pos))  # progress toward the waypoint
        terminated = False
        if float(np.linalg.norm(self.goal - self.pos)) < REACH:
            reward += GOAL_BONUS
            terminated = True
        self._advance()
        obs, info = self._obs_info()
        return obs, reward, terminated, False, info

    def waypoint_controller(self, obs, info):
        """Pursuit of a point ~2 m ahead on the start-goal line (the goal at the end).

        Forward pure pursuit where the needed curvature is within the rear steering's reach,
        reverse pursuit where the point is behind and reachable backwards, else a K-turn:
        reverse while swinging the forks toward the point.
        """
        s = float(np.dot(self.pos - self.start, self.dir))
        s_t = min(max(s, 0.0) + 2.0, self.length)
        target = self.start + s_t * self.dir
        if np.linalg.norm(self.goal - self.pos) < 2.0:
            target = self.goal
        d = target - self.pos
        dist = max(float(np.linalg.norm(d)), 1e-6)
        alpha = float(np.arctan2(d[1], d[0]) - self.th)
        alpha = float(np.arctan2(np.sin(alpha), np.cos(alpha)))
        kmax = np.sin(0.6) / WHEELBASE
        kappa = 2.0 * np.sin(abs(alpha)) / dist  # curvature of the arc through the point
        if kappa <= kmax or dist < REACH:
            if abs(alpha) <= np.pi / 2:
                # forward: heading rate = -v sin(delta)/L = v kappa  ->  sin(delta) = -L kappa
                k = 2.0 * np.sin(alpha) / dist
                return np.array([1.0, float(np.clip(-np.arcsin(np.clip(WHEELBASE * k, -1, 1)), -0.6, 0.6))], np.float32)
            back = float(np.arctan2(np.sin(alpha - np.pi), np.cos(alpha - np.pi)))
            k = 2.0 * np.sin(back) / dist
            # reverse: the backward direction turns at +sin(delta)/L
            return np.array([-1.0, float(np.clip(np.arcsin(np.clip(WHEELBASE * k, -1, 1)), -0.6, 0.6))], np.float32)
        # K-turn: back up while turning the forks toward the point
        return np.array([-1.0, float(0.6 * np.sign(alpha))], np.float32)


gym.register("Forklift-v0", entry_point=Forklift, max_episode_steps=MAX_STEPS, reward_threshold=13.5)  # check-env: 13.50 +- 0.38
