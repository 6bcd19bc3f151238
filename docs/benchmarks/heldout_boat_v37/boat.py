"""A small boat in a current that must reach a goal and keep station there.

3-DOF surface vessel (Fossen-style, unit mass in surge and sway):
  state x, y (world), psi (heading), u (surge), v (sway), r (yaw rate); u, v relative to the water.
  u' = T(a0) + v r - (Du u + Duu |u| u)            thrust: a0 * 1.0 forward, a0 * 0.5 backward
  v' = -u r   - (Dv v + Dvv |v| v)                 sway drag 4x surge drag: it slides in turns
  r' = a1 (Kr |u| + Kb) - (Dr r + Drr |r| r)       rudder scales with |u|, small bow thruster at rest
  x' = u cos psi - v sin psi + cx,  y' = u sin psi + v cos psi + cy   (constant current c, world frame)
Top speed ~1 m/s; current 0.25-0.35 m/s, random direction per episode. dt 0.1, 200 steps.
Waypoints every 0.5 m on the start-goal line, consumed within 0.3 m or when passed; the goal stays.
Reward: 10 x progress toward the current waypoint + 0.5 per step within 0.5 m of the goal.
"""
import math

import gymnasium as gym
import numpy as np

DT = 0.1
SUBSTEPS = 2
T_FWD, T_BWD = 1.0, 0.5
DU, DUU = 0.5, 0.5
DV, DVV = 2.0, 2.0
KR, KB = 2.0, 0.3
DR, DRR = 1.0, 0.5
WP_SPACING = 0.5
WP_RADIUS = 0.3
GOAL_RADIUS = 0.5
PROGRESS_SCALE = 10.0
HOLD_BONUS = 0.5


class Boat(gym.Env):
    metadata = {"render_modes": []}
    observation_space = gym.spaces.Box(-np.inf, np.inf, (15,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)
    position_period = None  # x, y do not wrap

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        rng = self.np_random
        self.x, self.y = rng.uniform(-2.0, 2.0, 2)
        self.psi = rng.uniform(-math.pi, math.pi)
        self.u = self.v = self.r = 0.0
        dist = rng.uniform(3.0, 6.0)
        ang = rng.uniform(-math.pi, math.pi)
        self.gx = self.x + dist * math.cos(ang)
        self.gy = self.y + dist * math.sin(ang)
        cang = rng.uniform(-math.pi, math.pi)
        cspd = rng.uniform(0.25, 0.35)
        self.cx, self.cy = cspd * math.cos(cang), cspd * math.sin(cang)
        # waypoints every 0.5 m along the line, the last one the goal
        n = max(1, int(math.ceil(dist / WP_SPACING)))
        s = np.minimum(np.arange(1, n + 1) * WP_SPACING, dist)
        s[-1] = dist
        self.sx, self.sy = self.x, self.y
        self.ex, self.ey = math.cos(ang), math.sin(ang)
        self.line_len = dist
        self.wp_s = s
        self.wps = np.stack([self.x + s * self.ex, self.y + s * self.ey], axis=1)
        self.k = 0
        self._advance()
        return self._obs(), self._info()

    def _advance(self):
        proj = (self.x - self.sx) * self.ex + (self.y - self.sy) * self.ey
        last = len(self.wp_s) - 1
        while self.k < last:
            wx, wy = self.wps[self.k]
            if self.wp_s[self.k] <= proj or math.hypot(wx - self.x, wy - self.y) < WP_RADIUS:
                self.k += 1
            else:
                break

    def _obs(self):
        c, s = math.cos(self.psi), math.sin(self.psi)
        wx, wy = self.wps[self.k]
        dwx, dwy = wx - self.x, wy - self.y
        dgx, dgy = self.gx - self.x, self.gy - self.y
        return np.array([
            dgx / 5.0, dgy / 5.0,                       # goal offset, world frame
            (c * dgx + s * dgy) / 5.0, (-s * dgx + c * dgy) / 5.0,  # goal offset, body frame
            dwx, dwy,                                   # waypoint offset, world frame (<= ~0.5 m)
            (c * dwx + s * dwy), (-s * dwx + c * dwy),  # waypoint offset, body frame
            c, s,
            self.u, self.v, self.r,
            (c * self.cx + s * self.cy) / 0.3, (-s * self.cx + c * self.cy) / 0.3,  # current, body frame
        ], dtype=np.float32)

    def _info(self):
        return {"position": np.array([self.x, self.y]), "waypoint": self.wps[self.k].copy(),
                "goal": np.array([self.gx, self.gy]), "waypoint_index": self.k}

    def step(self, action):
        a0 = min(1.0, max(-1.0, float(action[0])))
        a1 = min(1.0, max(-1.0, float(action[1])))
        thrust = a0 * (T_FWD if a0 >= 0.0 else T_BWD)
        wx, wy = self.wps[self.k]
        d_before = math.hypot(wx - self.x, wy - self.y)
        h = DT / SUBSTEPS
        x, y, psi, u, v, r = self.x, self.y, self.psi, self.u, self.v, self.r
        for _ in range(SUBSTEPS):
            du = thrust + v * r - (DU * u + DUU * abs(u) * u)
            dv = -u * r - (DV * v + DVV * abs(v) * v)
            dr = a1 * (KR * abs(u) + KB) - (DR * r + DRR * abs(r) * r)
            u += h * du
            v += h * dv
            r += h * dr
            psi += h * r
            c, s = math.cos(psi), math.sin(psi)
            x += h * (u * c - v * s + self.cx)
            y += h * (u * s + v * c + self.cy)
        self.x, self.y, self.u, self.v, self.r = x, y, u, v, r
        self.psi = (psi + math.pi) % (2.0 * math.pi) - math.pi
        d_after = math.hypot(wx - self.x, wy - self.y)
        reward = PROGRESS_SCALE * (d_before - d_after)
        if math.hypot(self.gx - self.x, self.gy - self.y) < GOAL_RADIUS:
            reward += HOLD_BONUS
        self._advance()
        return self._obs(), reward, False, False, self._info()

    def waypoint_controller(self, obs, info):
        """Aim the water-relative velocity at the waypoint, compensating the current (known here)."""
        px, py = self.x, self.y
        # look ahead along the start-goal line (1 m past the boat's projection, at most the goal)
        proj = (px - self.sx) * self.ex + (py - self.sy) * self.ey
        la = min(self.line_len, max(proj, 0.0) + 1.0)
        wx, wy = self.sx + la * self.ex, self.sy + la * self.ey
        dgoal = math.hypot(self.gx - px, self.gy - py)
        dx, dy = wx - px, wy - py
        dn = math.hypot(dx, dy)
        speed = min(0.9, 0.7 * dgoal)
        if dn > 1e-6:
            vgx, vgy = speed * dx / dn, speed * dy / dn
        else:
            vgx = vgy = 0.0
        # water-relative velocity needed: ground velocity minus current
        vwx, vwy = vgx - self.cx, vgy - self.cy
        u_des = math.hypot(vwx, vwy)
        psi_des = math.atan2(vwy, vwx)
        err = (psi_des - self.psi + math.pi) % (2.0 * math.pi) - math.pi
        rudder = 2.0 * err - 2.0 * self.r
        # keep some way on while turning: the rudder needs speed through the water
        u_cmd = max(u_des * math.cos(err), min(0.5, u_des) * (1.0 if abs(err) > 0.5 else 0.0))
        ff = DU * u_cmd + DUU * u_cmd * u_cmd
        thrust = ff + 1.5 * (u_cmd - self.u)
        return np.array([np.clip(thrust, -1.0, 1.0), np.clip(rudder, -1.0, 1.0)], dtype=np.float32)


gym.register("Boat-v0", entry_point=Boat, max_episode_steps=200, reward_threshold=72.4)  # check-env: 72.39 +- 3.50
