"""Push-v0: a 2-D point pusher moves a round puck along waypoints to a goal (pure NumPy).

Body
    pusher: a disc of radius 0.05, velocity control: it moves by 0.05 * action per step, action in [-1, 1]^2.
    puck:   a disc of radius 0.08 that moves only when the pusher touches it. Contact model: after the
            pusher moves, if the discs overlap the puck is pushed out along the line between the centres
            until they just touch, and half of that push is added to the puck's velocity; the puck then
            slides with that velocity, which friction scales by 0.6 every step (it stops within a few steps).
    arena:  [-1.5, 1.5]^2, both clipped to it.

Episode (at most 100 steps; it ends (terminated) once the puck's centre is within 0.06 of the goal)
    the puck starts uniformly in [-0.8, 0.8]^2, the goal 0.4-0.8 away in a random direction (inside the
    arena), the pusher behind the puck relative to the goal (0.01-0.06 from touching, up to 20 degrees off the
    puck-goal line).

Waypoints (spatial, about the PUCK)
    every 0.1 on the puck's start-goal line; a waypoint is consumed once the puck's projection on the line has
    passed it, or the puck is within 0.05 of it (the README's "reached or passed" advice). info["position"] is
    the puck's position, info["waypoint"] the next unconsumed waypoint (the goal once all are consumed).

Observation (16): pusher xy, puck xy, puck velocity xy (x10), goal xy, puck - pusher (x10), goal - puck (x3),
    waypoint - puck (x10), and the unit direction of the start-goal line (relative vectors scaled to about 1).

Reward (dense): 10 x (the puck's progress toward the goal this step) / (its start distance to the goal),
    plus a small potential term for the pusher approaching the puck (0.5 x the decrease of the
    pusher-puck surface gap); reaching the goal credits the remaining distance, so a success returns 10 plus
    the (small) approach term. Zero action returns 0.

Threshold: see README.md in this folder (90% of the way from zero action's return to the controller's,
    as check-env's controller line suggests).
"""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np

R_PUSHER = 0.05
R_PUCK = 0.08
R_SUM = R_PUSHER + R_PUCK
SPEED = 0.05
FRICTION = 0.6
ARENA = 1.5
SPACING = 0.1
REACH = 0.05
MAX_STEPS = 100
GOAL_RADIUS = 0.06


class Push(gym.Env):
    metadata = {"render_modes": []}

    observation_space = gym.spaces.Box(-np.inf, np.inf, (16,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)

    def __init__(self):
        super().__init__()
        self.pusher = np.zeros(2)
        self.puck = np.zeros(2)
        self.vel = np.zeros(2)
        self.goal = np.zeros(2)

    # --- waypoints -----------------------------------------------------------------------------------
    def _advance(self):
        # consume every waypoint the puck's projection on the start-goal line has passed, then any within REACH
        s = float(np.dot(self.puck - self.start, self.dir))
        while self.k < self.n_wp and (s >= self.wp_s[self.k] or
                                      np.linalg.norm(self.puck - self.wps[self.k]) < REACH):
            self.k += 1

    def _waypoint(self):
        return self.wps[self.k].copy() if self.k < self.n_wp else self.goal.copy()

    def _obs_info(self):
        wp = self._waypoint()
        obs = np.concatenate([
            self.pusher, self.puck, 10.0 * self.vel, self.goal,
            10.0 * (self.puck - self.pusher), 3.0 * (self.goal - self.puck), 10.0 * (wp - self.puck), self.dir,
        ]).astype(np.float32)
        info = {"position": self.puck.copy(), "waypoint": wp, "pusher": self.pusher.copy(),
                "goal": self.goal.copy()}
        return obs, info

    # --- gym API ---------------------------------------------------------------------------------------
    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        rng = self.np_random
        while True:
            self.puck = rng.uniform(-0.8, 0.8, 2)
            ang = rng.uniform(-math.pi, math.pi)
            dist = rng.uniform(0.4, 0.8)
            self.goal = self.puck + dist * np.array([math.cos(ang), math.sin(ang)])
            if np.all(np.abs(self.goal) <= 1.2):
                break
        self.start = self.puck.copy()
        d = self.goal - self.puck
        self.d0 = float(np.linalg.norm(d))
        self.dir = d / self.d0
        off = rng.uniform(-math.pi / 9, math.pi / 9)
        back = -np.array([self.dir[0] * math.cos(off) - self.dir[1] * math.sin(off),
                          self.dir[0] * math.sin(off) + self.dir[1] * math.cos(off)])
        self.pusher = self.puck + back * (R_SUM + rng.uniform(0.01, 0.06))
        self.vel = np.zeros(2)
        n = int(math.floor(self.d0 / SPACING))
        self.wp_s = SPACING * np.arange(1, n + 1)
        self.wp_s = self.wp_s[self.wp_s < self.d0 - 1e-9]
        self.wps = self.start + self.wp_s[:, None] * self.dir
        self.n_wp = len(self.wps)
        self.k = 0
        self.t = 0
        self._advance()
        return self._obs_info()

    def step(self, action):
        a = np.clip(np.asarray(action, dtype=np.float64).reshape(2), -1.0, 1.0)
        d_goal0 = float(np.linalg.norm(self.goal - self.puck))
        gap0 = float(np.linalg.norm(self.puck - self.pusher)) - R_SUM

        self.pusher = np.clip(self.pusher + SPEED * a, -ARENA, ARENA)
        # the puck slides with friction
        self.puck = self.puck + self.vel
        self.vel = self.vel * FRICTION
        # contact: push the puck out along the line between centres
        d = self.puck - self.pusher
        dist = float(np.linalg.norm(d))
        overlap = R_SUM - dist
        if overlap > 0.0:
            n = d / dist if dist > 1e-9 else self.dir.copy()
            self.puck = self.puck + overlap * n
            self.vel = self.vel + 0.5 * overlap * n
        clipped = np.clip(self.puck, -ARENA, ARENA)
        if np.any(clipped != self.puck):
            self.vel = np.zeros(2)
        self.puck = clipped
        if float(np.linalg.norm(self.vel)) < 1e-4:
            self.vel = np.zeros(2)

        d_goal1 = float(np.linalg.norm(self.goal - self.puck))
        gap1 = float(np.linalg.norm(self.puck - self.pusher)) - R_SUM
        reward = 10.0 * (d_goal0 - d_goal1) / self.d0 + 0.5 * (gap0 - gap1)
        terminated = d_goal1 < GOAL_RADIUS
        if terminated:  # on the goal: the remaining distance is credited, so a success returns 10 (+ the approach term)
            reward += 10.0 * d_goal1 / self.d0

        self.t += 1
        self._advance()
        obs, info = self._obs_info()
        info["is_success"] = terminated
        return obs, reward, terminated, False, info

    # --- scripted controller (oracle labels) -------------------------------------------------------------
    def waypoint_controller(self, obs, info):
        """Get behind the puck (relative to the waypoint) and push it toward the waypoint."""
        puck = np.asarray(info["position"], dtype=np.float64)
        wp = np.asarray(info["waypoint"], dtype=np.float64)
        pusher = self.pusher
        u = wp - puck
        nu = float(np.linalg.norm(u))
        if nu < 1e-6:
            u = self.goal - puck
            nu = float(np.linalg.norm(u))
            if nu < 1e-6:
                return np.zeros(2, dtype=np.float32)
        u = u / nu
        rel = pusher - puck
        dist = float(np.linalg.norm(rel))
        along = float(np.dot(rel, u))  # negative: behind the puck
        lateral = rel - along * u
        lat = float(np.linalg.norm(lateral))
        if along < -0.5 * R_SUM and lat < 0.3 * R_SUM:
            # behind and roughly aligned: push through the puck's centre toward the waypoint, correcting sideways
            depth = min(0.04, 0.4 * float(np.linalg.norm(self.goal - puck)))  # gentle near the goal
            target = puck - u * (R_SUM - depth)
            v = (target - pusher) / SPEED
        else:
            # go around: aim at a point behind the puck; if the puck is in the way, step tangentially
            target = puck - u * (R_SUM + 0.05)
            v = (target - pusher) / SPEED
            if dist < R_SUM + 0.06 and along > -0.5 * R_SUM:
                side = lateral / lat if lat > 1e-6 else np.array([-u[1], u[0]])
                v = side * 1.0 + (rel / max(dist, 1e-6)) * 0.5 - u * 0.5
        m = float(np.max(np.abs(v)))
        if m > 1.0:
            v = v / m
        return v.astype(np.float32)


gym.register("Push-v0", entry_point=Push, max_episode_steps=MAX_STEPS, reward_threshold=9.0)
