"""Two held-out bodies for shaped-es (pure numpy, one env instance per episode).

Hover3D-v0
    3-D point mass under force control, linear drag, gravity NOT compensated (the policy must hold
    F_z = g/gain = 0.5 just to hover).  dt = 0.05, 100 steps (5 s).
        v += dt * (gain*F - drag*v - g*e_z);  p += dt * v     (gain 1.0, drag 1.0, g 0.5)
    Start p0 ~ U[-1,1]^3 at rest, goal = p0 + u * U(0.8, 1.6) with u a random unit vector.
    Spatial waypoints every 0.1 along the start->goal line; waypoint k is consumed once the body comes
    within 0.15 of it (or of any later one); info['waypoint'] is the first unconsumed one (the goal
    after all are consumed).
    obs (9): p, v, goal - p.   act (3): forces in [-1, 1].
    reward: r_t = 10*(d_{t-1} - d_t)/d0 - 0.02*d_t/d0  (d = |goal - p|)
        The progress term telescopes to 10*(1 - d_T/d0): 10 for ending on the goal, 0 for ending where
        it started, negative for drifting away (falling under gravity).  The time term costs 0.02 per
        step per unit of remaining normalised distance (~0.3-0.6 for a fast arrival).
    reward_threshold 8.5: the return of a body that ends within ~10% of d0 of the goal (10*(1-0.1)=9)
    after a prompt arrival (time cost ~0.5).  A hand-tuned PD controller (waypoint_controller, with
    exact gravity feed-forward) gets 9.49 +- 0.12 over 50 episodes, zero action -14.1 (check.py), so 8.5 is "hovers at the goal", not
    "passes near it".

Tractor-v0
    Car-like (kinematic bicycle) body one order above a unicycle: actions are the linear
    ACCELERATION and the STEERING RATE.  dt = 0.1, 150 steps (15 s).
        v += dt*2*a1 (v in [-0.5, 1.5]);  delta += dt*1.5*a2 (|delta| <= 0.6);
        theta += dt*v*tan(delta)/L (L = 0.5);  p += dt*v*(cos theta, sin theta)
    Start p0 ~ U[-2,2]^2 at rest, delta = 0; goal at chord length U(4, 7) in a random direction; the
    path is a circular arc from p0 to the goal with a random signed bulge (sagitta = U(0.15, 0.35) of
    the chord).  The start heading is the arc's initial tangent + U(-0.5, 0.5) rad.
    Timed waypoints: the schedule w(t) moves along the arc with a smooth-step profile, reaching the
    goal at step 120 and staying there; info['waypoint'] after step t is w(t+1) (where the body
    should be one step later).
    obs (11): cos th, sin th, v, delta, R(-th)(w(t+1) - p), R(-th)(w(t+10) - p), R(-th)(goal - p)/5,
              t/150 (body-frame vectors to the schedule one and ten steps ahead, and to the goal).
    act (2): [acceleration, steering rate] in [-1, 1].
    reward: r_t = -0.1 * min(|p_t - w(t)|, 5)  (tracking error to the schedule, metres, capped).
        Standing still scores about -30 to -55; perfect tracking 0.
    reward_threshold -6.0: a mean tracking error of 0.4 m over the 150 steps (the start heading
    error alone costs ~0.5-1.5); a scripted pure-pursuit + speed-PD controller (waypoint_controller)
    gets -0.69 +- 0.12 over 50 episodes, zero action -48.7, random actions -48 (check.py).  -6 is
    ~88% of the way from standing still to the controller.
"""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np


class Hover3D(gym.Env):
    metadata = {"render_modes": []}
    dt, gain, drag, g = 0.05, 1.0, 1.0, 0.5
    spacing, radius = 0.1, 0.15
    observation_space = gym.spaces.Box(-np.inf, np.inf, (9,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (3,), np.float32)

    def _info(self):
        w = self.goal if self.k >= len(self.wps) else self.wps[self.k]
        return {"position": self.p.copy(), "waypoint": w.copy()}

    def _obs(self):
        return np.concatenate([self.p, self.v, self.goal - self.p]).astype(np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        r = self.np_random
        self.p = r.uniform(-1.0, 1.0, 3)
        u = r.normal(size=3)
        u /= np.linalg.norm(u)
        dist = r.uniform(0.8, 1.6)
        self.goal = self.p + u * dist
        self.v = np.zeros(3)
        n = int(dist / self.spacing)
        self.wps = self.p + np.outer(np.arange(1, n + 1) * self.spacing, u)
        self.wps = np.vstack([self.wps, self.goal[None]])
        self.k = 0
        self.d0 = dist
        self.d = dist
        return self._obs(), self._info()

    def step(self, action):
        F = np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0)
        acc = self.gain * F - self.drag * self.v
        acc[2] -= self.g
        self.v = self.v + self.dt * acc
        self.p = self.p + self.dt * self.v
        if self.k < len(self.wps):
            near = np.nonzero(np.linalg.norm(self.wps[self.k:] - self.p, axis=1) < self.radius)[0]
            if near.size:
                self.k += int(near[-1]) + 1
        d = float(np.linalg.norm(self.goal - self.p))
        rew = 10.0 * (self.d - d) / self.d0 - 0.02 * d / self.d0
        self.d = d
        return self._obs(), rew, False, False, self._info()

    def waypoint_controller(self, obs, info):
        """PD toward the goal with gravity feed-forward (used only to justify the threshold)."""
        e = self.goal - self.p
        F = (3.0 * e - 2.5 * self.v + self.drag * self.v) / self.gain
        F[2] += self.g / self.gain
        return np.clip(F, -1, 1).astype(np.float32)


class Tractor(gym.Env):
    metadata = {"render_modes": []}
    dt, L, horizon, arrive = 0.1, 0.5, 150, 120
    observation_space = gym.spaces.Box(-np.inf, np.inf, (11,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)

    def _sched(self, t):
        s = min(1.0, t / self.arrive)
        s = s * s * (3.0 - 2.0 * s)  # smooth-step: starts and ends at rest
        ang = self.a0 + self.sweep * s
        return self.c + self.R * np.array([math.cos(ang), math.sin(ang)])

    def _info(self):
        return {"position": self.p.copy(), "waypoint": self._sched(self.t + 1)}

    def _obs(self):
        c, s = math.cos(self.th), math.sin(self.th)

        def body(d):
            return (c * d[0] + s * d[1], -s * d[0] + c * d[1])

        w1 = body(self._sched(self.t + 1) - self.p)
        w10 = body(self._sched(self.t + 10) - self.p)
        g = body(self.goal - self.p)
        return np.array([c, s, self.v, self.delta, *w1, *w10, g[0] / 5, g[1] / 5, self.t / self.horizon],
                        np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        r = self.np_random
        self.p = r.uniform(-2.0, 2.0, 2)
        phi = r.uniform(-math.pi, math.pi)
        chord = r.uniform(4.0, 7.0)
        self.goal = self.p + chord * np.array([math.cos(phi), math.sin(phi)])
        sag = chord * r.uniform(0.15, 0.35) * (1 if r.random() < 0.5 else -1)
        # circle through p and goal with sagitta sag: radius R, half-angle alpha
        h = chord / 2
        R = (h * h + sag * sag) / (2 * abs(sag))
        alpha = math.asin(min(1.0, h / R))  # sag < R here (sag/chord <= 0.35 < 0.5)
        mid = (self.p + self.goal) / 2
        nrm = np.array([-math.sin(phi), math.cos(phi)])  # left normal of the chord
        side = 1.0 if sag > 0 else -1.0  # bulge to the left (+) or right (-)
        self.c = mid - side * nrm * (R - abs(sag))
        self.R = R
        self.a0 = math.atan2(*(self.p - self.c)[::-1])
        self.sweep = -side * 2 * alpha  # bulge left -> clockwise around the centre
        # check the end of the sweep is the goal (else flip direction)
        end = self.c + R * np.array([math.cos(self.a0 + self.sweep), math.sin(self.a0 + self.sweep)])
        if np.linalg.norm(end - self.goal) > 1e-6:
            self.sweep = -self.sweep
        tang = self.sweep / abs(self.sweep) * np.array([-math.sin(self.a0), math.cos(self.a0)])
        self.th = math.atan2(tang[1], tang[0]) + r.uniform(-0.5, 0.5)
        self.v, self.delta, self.t = 0.0, 0.0, 0
        return self._obs(), self._info()

    def step(self, action):
        a = np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0)
        dt = self.dt
        self.v = min(1.5, max(-0.5, self.v + dt * 2.0 * float(a[0])))
        self.delta = min(0.6, max(-0.6, self.delta + dt * 1.5 * float(a[1])))
        self.th += dt * self.v * math.tan(self.delta) / self.L
        self.p = self.p + dt * self.v * np.array([math.cos(self.th), math.sin(self.th)])
        self.t += 1
        err = float(np.linalg.norm(self.p - self._sched(self.t)))
        return self._obs(), -0.1 * min(err, 5.0), False, False, self._info()

    def waypoint_controller(self, obs, info):
        """Pure pursuit of the schedule 10 steps ahead + speed P-control (threshold justification)."""
        tgt = self._sched(self.t + 10)
        d = tgt - self.p
        c, s = math.cos(self.th), math.sin(self.th)
        x, y = c * d[0] + s * d[1], -s * d[0] + c * d[1]
        l2 = max(x * x + y * y, 1e-6)
        want_delta = math.atan(2 * self.L * y / l2)
        vs = np.linalg.norm(self._sched(self.t + 2) - self._sched(self.t + 1)) / self.dt
        e = self._sched(self.t + 1) - self.p
        want_v = vs + 1.5 * (c * e[0] + s * e[1])
        a1 = (want_v - self.v) * 5.0
        a2 = (want_delta - self.delta) * 4.0
        return np.clip([a1, a2], -1, 1).astype(np.float32)


gym.register("Hover3D-v0", entry_point=Hover3D, max_episode_steps=100, reward_threshold=8.5)
gym.register("Tractor-v0", entry_point=Tractor, max_episode_steps=150, reward_threshold=-6.0)
