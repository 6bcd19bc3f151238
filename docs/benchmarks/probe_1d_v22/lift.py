"""Lift-v0: a vertical lift (a thruster under gravity), 1-D height, following a timed schedule.

Dynamics (dt = 0.05 s, 120 steps = 6 s): m dv/dt = T - m g - c v, m = 1 kg, g = 9.81, c = 0.5 N s/m,
thrust T in [0, 16] N (the middle, 8 N, is below the 9.81 N hover thrust: "zero action" sinks; full
thrust climbs at up to 6.2 m/s^2, no thrust falls at g). Floor at 0 m and ceiling at 4 m (stop, v = 0).
Start and target heights uniform in [0.5, 3.5] m, at least 0.5 m apart; at rest at the start.

Schedule (timed waypoints): h_ref(t) = start + (target - start) * s(t / 60), s the smoothstep
3u^2 - 2u^3 clipped at u = 1: from start to target over the first 60 steps (3 s), then holding.
info["waypoint"] = h_ref(t + 1) (where the schedule puts the lift after the next step).
Reward: -|h - h_ref(t)| after each step (t the steps taken); the schedule's height and phase are in
the observation, since the policy never sees info.
Observation (7): h, v, target, target - h, h_ref(t) - h, h_ref(t+1) - h, t / 120.
"""
import gymnasium as gym
import numpy as np

DT, MASS, G, DAMP = 0.05, 1.0, 9.81, 0.5
T_MIN, T_MAX = 0.0, 16.0
H_MIN, H_MAX = 0.0, 4.0
MOVE_STEPS, MAX_STEPS = 60, 120


def _smooth(u):
    u = min(max(u, 0.0), 1.0)
    return u * u * (3.0 - 2.0 * u)


class Lift(gym.Env):
    observation_space = gym.spaces.Box(-10.0, 10.0, (7,), np.float32)
    action_space = gym.spaces.Box(T_MIN, T_MAX, (1,), np.float32)  # thrust, N

    def _ref(self, t):
        return self.start + (self.target - self.start) * _smooth(t / MOVE_STEPS)

    def _ref_vel(self, t):
        u = t / MOVE_STEPS
        if u <= 0.0 or u >= 1.0:
            return 0.0
        return (self.target - self.start) * 6.0 * u * (1.0 - u) / (MOVE_STEPS * DT)

    def _ref_acc(self, t):
        u = t / MOVE_STEPS
        if u <= 0.0 or u >= 1.0:
            return 0.0
        return (self.target - self.start) * (6.0 - 12.0 * u) / (MOVE_STEPS * DT) ** 2

    def _obs_info(self):
        r0, r1 = self._ref(self.t), self._ref(self.t + 1)
        obs = np.array([self.h, self.v, self.target, self.target - self.h, r0 - self.h, r1 - self.h,
                        self.t / MAX_STEPS], np.float32)
        info = {"position": np.array([self.h]), "waypoint": np.array([r1])}
        return obs, info

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        rng = self.np_random
        self.start = float(rng.uniform(0.5, 3.5))
        self.target = float(rng.uniform(0.5, 3.5))
        while abs(self.target - self.start) < 0.5:
            self.target = float(rng.uniform(0.5, 3.5))
        self.h, self.v, self.t = self.start, 0.0, 0
        return self._obs_info()

    def step(self, action):
        thrust = float(np.clip(np.asarray(action, dtype=np.float64).reshape(-1)[0], T_MIN, T_MAX))
        self.v += DT * (thrust - MASS * G - DAMP * self.v) / MASS
        self.h += DT * self.v
        if self.h < H_MIN or self.h > H_MAX:  # floor / ceiling
            self.h, self.v = float(np.clip(self.h, H_MIN, H_MAX)), 0.0
        self.t += 1
        reward = -abs(self.h - self._ref(self.t))
        obs, info = self._obs_info()
        return obs, reward, False, False, info

    def waypoint_controller(self, obs, info):
        """Track the timed waypoint: gravity and damping feedforward, the schedule's acceleration,
        and PD on the waypoint (h_ref(t+1)) and the schedule's velocity."""
        w = float(info["waypoint"][0])
        acc = self._ref_acc(self.t) + 40.0 * (w - self.h) + 10.0 * (self._ref_vel(self.t) - self.v)
        thrust = MASS * (G + acc) + DAMP * self.v
        return np.array([np.clip(thrust, T_MIN, T_MAX)], np.float32)


# reward_threshold -22.0. Measured by stepping env.unwrapped.waypoint_controller on reset(seed=1000..1019)
# (20 episodes): controller -1.25 (+-0.57), zero action (8 N, sinks to the floor) -211.0, uniform random
# thrust -200.0; `shaped-es check-env lift:Lift-v0` (10 episodes): -1.35 / -232.2 / -216.1.
# The README's "0.9 x the controller's return" gives -1.13 (-1.22 in check-env), ABOVE the controller's
# own return, since the returns are negative. Used instead: 90% of the way from zero action to the
# controller, zero + 0.9 * (controller - zero) = -211.0 + 0.9 * 209.8 = -22.2 -> -22.0 (the same as
# 0.9 x the controller wherever zero action returns 0, as on the suite's and Rail-v0's progress rewards):
# a mean tracking error of about 0.18 m per step.
gym.register("Lift-v0", entry_point=Lift, max_episode_steps=MAX_STEPS, reward_threshold=-22.0)
