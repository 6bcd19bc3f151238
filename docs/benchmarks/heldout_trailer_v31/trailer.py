"""A kinematic car towing a trailer (articulated), steered toward a goal 2-4 m from the trailer.

State: tractor rear axle (x, y) = hitch point, tractor heading theta, hitch angle phi
(trailer heading psi = theta + phi).
Action (2-D in [-1, 1]): speed v = a1 m/s (reverse allowed), steering delta = 0.5 * a2 rad.
Kinematics (dt 0.1 s, explicit Euler):
    x' = v cos theta, y' = v sin theta, theta' = v/L tan delta,
    phi' = -v/L tan delta - v/L_t sin phi          (L = 0.5 m, L_t = 0.8 m)
Jackknife (|phi| > 1.3 rad) ends the episode with a penalty of -5.
The reported position is the TRAILER's rear axle: (x, y) - L_t (cos psi, sin psi).
Waypoints every 0.4 m on the straight line from the trailer's start to the goal (the last one is the goal),
consumed within 0.2 m or once the trailer's projection on the line has passed them.
Reward: 10 * (progress of the trailer toward the current waypoint) / (start-goal distance) per step
(about 10 over a whole route), +5 and the end when the trailer is within 0.2 m of the goal.
200 steps.
Observation (6): goal offset in the trailer's frame / 4, current waypoint offset in the trailer's frame / 0.5
(clipped to [-3, 3]), sin phi, cos phi.
"""

import gymnasium as gym
import numpy as np

L = 0.5
LT = 0.8
DT = 0.1
SPACING = 0.4
REACH = 0.2
GOAL_RADIUS = 0.2
JACKKNIFE = 1.3
BONUS = 5.0
PENALTY = 5.0


class Trailer(gym.Env):
    metadata = {"render_modes": []}
    observation_space = gym.spaces.Box(-5.0, 5.0, (6,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)
    position_period = None  # x, y of the trailer: nothing wraps

    # --- geometry -------------------------------------------------------------------------
    def _trailer_pos(self):
        psi = self.theta + self.phi
        return np.array([self.x - LT * np.cos(psi), self.y - LT * np.sin(psi)])

    def _waypoint(self):
        return self.waypoints[self.k].copy()

    def _advance(self, p):
        n = len(self.waypoints)
        proj = float(np.dot(p - self.start, self.u))
        while self.k < n - 1:
            w = self.waypoints[self.k]
            if np.linalg.norm(w - p) < REACH or proj >= (self.k + 1) * SPACING:
                self.k += 1
            else:
                break

    def _obs_info(self):
        p = self._trailer_pos()
        psi = self.theta + self.phi
        c, s = np.cos(psi), np.sin(psi)
        rot = np.array([[c, s], [-s, c]])  # world -> trailer frame
        g = rot @ (self.goal - p) / 4.0
        w = np.clip(rot @ (self.waypoints[self.k] - p) / 0.5, -3.0, 3.0)
        obs = np.concatenate([g, w, [np.sin(self.phi), np.cos(self.phi)]]).astype(np.float32)
        info = {"position": p, "waypoint": self._waypoint()}
        return obs, info

    # --- gym API ---------------------------------------------------------------------------
    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        r = self.np_random
        self.x, self.y = r.uniform(-2.0, 2.0, 2)
        self.theta = r.uniform(-np.pi, np.pi)
        self.phi = r.uniform(-0.3, 0.3)
        self.start = self._trailer_pos()
        dist = r.uniform(2.0, 4.0)
        ang = r.uniform(-np.pi, np.pi)
        self.u = np.array([np.cos(ang), np.sin(ang)])
        self.goal = self.start + dist * self.u
        self.dist0 = dist
        n = int(np.ceil(dist / SPACING))
        self.waypoints = [self.start + min((i + 1) * SPACING, dist) * self.u for i in range(n)]
        self.waypoints[-1] = self.goal.copy()
        self.k = 0
        return self._obs_info()

    def step(self, action):
        a = np.clip(np.asarray(action, dtype=float), -1.0, 1.0)
        v, delta = a[0], 0.5 * a[1]
        p0 = self._trailer_pos()
        w = self.waypoints[self.k]
        d0 = np.linalg.norm(w - p0)
        tan_d = np.tan(delta)
        self.x += DT * v * np.cos(self.theta)
        self.y += DT * v * np.sin(self.theta)
        dphi = -v / L * tan_d - v / LT * np.sin(self.phi)
        self.theta += DT * v / L * tan_d
        self.phi += DT * dphi
        self.theta = (self.theta + np.pi) % (2 * np.pi) - np.pi
        p = self._trailer_pos()
        reward = 10.0 * (d0 - np.linalg.norm(w - p)) / self.dist0
        terminated = False
        if abs(self.phi) > JACKKNIFE:
            reward -= PENALTY
            terminated = True
        elif np.linalg.norm(self.goal - p) < GOAL_RADIUS:
            reward += BONUS
            terminated = True
        self._advance(p)
        obs, info = self._obs_info()
        return obs, float(reward), terminated, False, info

    # --- oracle ----------------------------------------------------------------------------
    def waypoint_controller(self, obs, info):
        """Forward driving only (pulling is stable): steer the TRAILER, with the hitch angle as its input.

        The trailer pure-pursues a point 1.0 m ahead of its projection on the start-goal line (capped at
        the goal); its heading error e asks for psi' = 2 e, hence a hitch angle phi_d with
        sin(phi_d) = -2 e L_t / v (|phi_d| <= 1); the wheel then drives phi to phi_d at rate 2:
        tan(delta) = -(L / v) (2 (phi_d - phi) + v / L_t sin(phi)). 50/50 seeded episodes reach the goal,
        none jackknifes (mean return ~11.3 against zero action's 0).
        """
        p = self._trailer_pos()
        proj = float(np.dot(p - self.start, self.u))
        aim = self.start + min(max(proj, 0.0) + 1.0, self.dist0) * self.u
        psi = self.theta + self.phi
        err = np.arctan2(aim[1] - p[1], aim[0] - p[0]) - psi
        err = (err + np.pi) % (2 * np.pi) - np.pi
        v = 1.0
        phi_d = np.arcsin(np.clip(-2.0 * err * LT / v, -np.sin(1.0), np.sin(1.0)))
        tan_d = -(L / v) * (2.0 * (phi_d - self.phi) + v / LT * np.sin(self.phi))
        return np.array([v, np.clip(np.arctan(tan_d) / 0.5, -1.0, 1.0)], dtype=np.float32)


# threshold: check-env suggested 10.20 +- 0.45 (90% of zero action 0 -> controller 11.34); 10.0 is inside
# that interval: the goal bonus (5) plus ~5 of the 10 progress points, i.e. most test episodes reach the goal.
gym.register("Trailer-v0", entry_point=Trailer, max_episode_steps=200, reward_threshold=10.0)
