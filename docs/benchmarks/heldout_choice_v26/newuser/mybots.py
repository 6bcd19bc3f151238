"""Two planar robots with choice action spaces, for shaped-es.

Crawler-v0: unicycle-like robot, action MultiDiscrete([3, 5]) = (gear, steering).
    gear: 0 stop, 1 slow forward, 2 fast forward
    steering: 0 straight, 1 gentle left, 2 gentle right, 3 hard left, 4 hard right
    action (0, 0) = stop, straight = the no-op.
Valves-v0: a puck on a table, 6 air jets at 60 degrees apart, MultiBinary(6); all off = coast (no-op).

Both: random start and goal (1.0-1.8 apart), spatial waypoints every 0.15 on the start-goal line,
consumed when reached (within 0.075) or passed (projection on the line); dense reward
10 * progress / initial distance (so ~10 for reaching the goal); episode terminates at the goal.
"""
import itertools

import gymnasium as gym
import numpy as np

SPACING = 0.15
REACH = 0.075
GOAL_RADIUS = 0.08
ARENA = 2.5


class _WaypointTask(gym.Env):
    metadata = {"render_modes": ["rgb_array"], "render_fps": 20}

    def __init__(self, render_mode=None):
        self.render_mode = render_mode

    # --- waypoints -------------------------------------------------------
    def _init_task(self):
        self.start = self.np_random.uniform(-1.0, 1.0, 2)
        ang = self.np_random.uniform(-np.pi, np.pi)
        dist = self.np_random.uniform(1.0, 1.8)
        self.goal = self.start + dist * np.array([np.cos(ang), np.sin(ang)])
        self.d0 = dist
        n = int(np.ceil(dist / SPACING))
        self.waypoints = [self.start + min(1.0, (k + 1) * SPACING / dist) * (self.goal - self.start)
                          for k in range(n)]
        self.wp_idx = 0
        self.t = 0

    def _advance_waypoints(self):
        u = (self.goal - self.start) / self.d0
        proj = float(np.dot(self.pos - self.start, u))
        while self.wp_idx < len(self.waypoints) - 1:
            w = self.waypoints[self.wp_idx]
            wproj = float(np.dot(w - self.start, u))
            if proj >= wproj or np.linalg.norm(w - self.pos) < REACH:
                self.wp_idx += 1
            else:
                break

    def _info(self):
        return {"position": self.pos.copy(), "waypoint": self.waypoints[self.wp_idx].copy()}

    def _reward_done(self, prev_d):
        d = float(np.linalg.norm(self.goal - self.pos))
        r = 10.0 * (prev_d - d) / self.d0
        return r, d < GOAL_RADIUS

    # --- rendering -------------------------------------------------------
    def render(self):
        if self.render_mode != "rgb_array":
            return None
        S = 200
        img = np.full((S, S, 3), 255, np.uint8)

        def px(p):
            q = ((np.asarray(p) + ARENA) / (2 * ARENA) * (S - 1)).astype(int)
            return np.clip(q, 2, S - 3)

        def dot(p, col, r=2):
            x, y = px(p)
            img[S - 1 - (y + r): S - (y - r), x - r: x + r + 1] = col

        for w in self.waypoints:
            dot(w, (180, 180, 180), 1)
        dot(self.waypoints[self.wp_idx], (0, 160, 0), 2)
        dot(self.goal, (220, 0, 0), 3)
        dot(self.pos, (0, 0, 200), 3)
        return img


class Crawler(_WaypointTask):
    """Unicycle: x += v cos(th), y += v sin(th), th += w (old heading)."""

    SPEEDS = np.array([0.0, 0.02, 0.05])
    TURNS = np.array([0.0, 0.12, -0.12, 0.35, -0.35])

    def __init__(self, render_mode=None):
        super().__init__(render_mode)
        self.action_space = gym.spaces.MultiDiscrete([3, 5])
        # pos (2), cos th, sin th, goal - pos (2), waypoint - pos (2)
        self.observation_space = gym.spaces.Box(-10.0, 10.0, (8,), np.float32)

    def _obs(self):
        return np.concatenate([self.pos / 2.0, [np.cos(self.th), np.sin(self.th)], self.goal - self.pos,
                               self.waypoints[self.wp_idx] - self.pos]).astype(np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self._init_task()
        self.pos = self.start.copy()
        self.th = self.np_random.uniform(-np.pi, np.pi)
        return self._obs(), self._info()

    def step(self, action):
        a = np.asarray(action).astype(int).reshape(-1)
        v, w = self.SPEEDS[a[0]], self.TURNS[a[1]]
        prev_d = float(np.linalg.norm(self.goal - self.pos))
        self.pos = np.clip(self.pos + v * np.array([np.cos(self.th), np.sin(self.th)]), -ARENA, ARENA)
        self.th = (self.th + w + np.pi) % (2 * np.pi) - np.pi
        self.t += 1
        self._advance_waypoints()
        r, done = self._reward_done(prev_d)
        return self._obs(), r, done, False, self._info()

    def waypoint_controller(self, obs, info):
        d = info["waypoint"] - info["position"]
        if np.linalg.norm(self.goal - self.pos) < 0.2:
            d = self.goal - self.pos
        e = (np.arctan2(d[1], d[0]) - self.th + np.pi) % (2 * np.pi) - np.pi
        if abs(e) > 0.25:
            steer = 3 if e > 0 else 4
        elif abs(e) > 0.06:
            steer = 1 if e > 0 else 2
        else:
            steer = 0
        if abs(e) > 1.2:
            gear = 0
        elif abs(e) > 0.5 or np.linalg.norm(self.goal - self.pos) < 0.12:
            gear = 1
        else:
            gear = 2
        return np.array([gear, steer], dtype=np.int64)


class Valves(_WaypointTask):
    """Puck pushed by 6 on/off air jets at 0, 60, ..., 300 degrees; velocity damping (friction)."""

    FORCE = 0.004
    FRICTION = 0.1
    DIRS = np.array([[np.cos(k * np.pi / 3), np.sin(k * np.pi / 3)] for k in range(6)])
    COMBOS = np.array(list(itertools.product([0, 1], repeat=6)), dtype=np.int8)

    def __init__(self, render_mode=None):
        super().__init__(render_mode)
        self.action_space = gym.spaces.MultiBinary(6)
        # pos (2), vel*10 (2), goal - pos (2), waypoint - pos (2)
        self.observation_space = gym.spaces.Box(-10.0, 10.0, (8,), np.float32)

    def _obs(self):
        return np.concatenate([self.pos / 2.0, self.vel * 10.0, self.goal - self.pos,
                               self.waypoints[self.wp_idx] - self.pos]).astype(np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self._init_task()
        self.pos = self.start.copy()
        self.vel = np.zeros(2)
        return self._obs(), self._info()

    def step(self, action):
        a = np.asarray(action).astype(np.float64).reshape(6)
        prev_d = float(np.linalg.norm(self.goal - self.pos))
        force = self.FORCE * (a @ self.DIRS)
        self.vel = (1.0 - self.FRICTION) * self.vel + force
        self.pos = self.pos + self.vel
        out = np.abs(self.pos) > ARENA
        self.vel[out] = 0.0
        self.pos = np.clip(self.pos, -ARENA, ARENA)
        self.t += 1
        self._advance_waypoints()
        r, done = self._reward_done(prev_d)
        return self._obs(), r, done, False, self._info()

    def waypoint_controller(self, obs, info):
        aim = self.waypoints[min(self.wp_idx + 1, len(self.waypoints) - 1)]
        if np.linalg.norm(self.goal - self.pos) < 0.3:
            aim = self.goal
        # desired velocity toward the aim, capped; the force that gets there next step
        d = aim - self.pos
        v_des = 0.06 * d / max(np.linalg.norm(d), 0.06)
        f_des = v_des - (1.0 - self.FRICTION) * self.vel
        forces = self.FORCE * (self.COMBOS @ self.DIRS)
        best = np.argmin(np.sum((forces - f_des) ** 2, axis=1))
        return self.COMBOS[best].copy()


gym.register("Crawler-v0", entry_point=Crawler, max_episode_steps=120)
gym.register("Valves-v0", entry_point=Valves, max_episode_steps=100)
