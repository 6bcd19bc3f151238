"""A planar 3-link arm with joint-velocity control, following timed waypoints to a random target.

Body: links 0.4, 0.3, 0.2 m, base at the origin, joint angles q (relative, radians), clipped at +-2.5 rad.
Action: 3 joint velocities in [-1, 1], scaled by 2.0 rad/s; q += qdot * dt, dt = 0.05 s. 100 steps.
Redundant: 3 joints for a 2-D fingertip.

Episode: random initial joint angles, and a random reachable target (the fingertip of random joint angles
within the limits) at least 0.3 m from the start fingertip.

Waypoints (timed, on a schedule): the fingertip's straight line from the start fingertip to the target,
one waypoint every 5 steps, the line done at step 50 (waypoints due at steps 5, 10, ..., 50 = the target),
then the target held for the remaining 50 steps.

Reward after step t -> t+1: minus the fingertip's distance to the scheduled waypoint due next (the one due
at step 5 * ceil((t+1) / 5)), plus a bonus of 0.5 per step when the schedule has reached the target and
the fingertip is within 0.05 m of it.

Observation (16): cos q (3), sin q (3), q / 2.5 (3), fingertip (2), target - fingertip (2),
current waypoint - fingertip (2), phase t / T (1). The phase and the waypoint's offset are in the
observation because the reward follows the schedule (README checklist).

info: "position" = fingertip (2,), "waypoint" = the scheduled waypoint the next step's reward is measured
against (2,). `waypoint_controller(obs, info)`: Jacobian pseudo-inverse toward info["waypoint"].
"""

import gymnasium as gym
import numpy as np

LINKS = np.array([0.4, 0.3, 0.2])
Q_LIM = 2.5
QDOT_SCALE = 2.0
DT = 0.05
T_MAX = 100
WP_EVERY = 5
LINE_STEPS = 50
MIN_DIST = 0.3
BONUS = 0.5
BONUS_RADIUS = 0.05

# 0.9 of the way from zero action's mean return to the waypoint controller's (measure_threshold.py)
REWARD_THRESHOLD = 0.9


def fk(q):
    a = np.cumsum(q)
    return np.array([np.sum(LINKS * np.cos(a)), np.sum(LINKS * np.sin(a))])


def jacobian(q):
    a = np.cumsum(q)
    J = np.zeros((2, 3))
    for j in range(3):
        J[0, j] = -np.sum(LINKS[j:] * np.sin(a[j:]))
        J[1, j] = np.sum(LINKS[j:] * np.cos(a[j:]))
    return J


class Arm3(gym.Env):
    metadata = {"render_modes": []}

    observation_space = gym.spaces.Box(-np.inf, np.inf, (16,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (3,), np.float32)

    def _waypoint(self, t):
        """The scheduled waypoint due next at time t (the one due at step WP_EVERY * ceil(t / WP_EVERY))."""
        due = WP_EVERY * int(np.ceil(t / WP_EVERY))
        frac = min(1.0, due / LINE_STEPS)
        return self.start + frac * (self.target - self.start)

    def _obs_info(self):
        tip = fk(self.q)
        wp = self._waypoint(self.t + 1)  # the waypoint the next step's reward is measured against
        obs = np.concatenate(
            [np.cos(self.q), np.sin(self.q), self.q / Q_LIM, tip, self.target - tip, wp - tip, [self.t / T_MAX]]
        ).astype(np.float32)
        info = {"position": tip.copy(), "waypoint": wp.copy()}
        return obs, info

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        rng = self.np_random
        self.q = rng.uniform(-2.0, 2.0, 3)
        self.start = fk(self.q)
        while True:
            self.target = fk(rng.uniform(-Q_LIM, Q_LIM, 3))
            if np.linalg.norm(self.target - self.start) >= MIN_DIST:
                break
        self.t = 0
        return self._obs_info()

    def step(self, action):
        a = np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0)
        self.q = np.clip(self.q + QDOT_SCALE * a * DT, -Q_LIM, Q_LIM)
        self.t += 1
        tip = fk(self.q)
        wp = self._waypoint(self.t)
        reward = -float(np.linalg.norm(tip - wp))
        if self.t >= LINE_STEPS and np.linalg.norm(tip - self.target) < BONUS_RADIUS:
            reward += BONUS
        obs, info = self._obs_info()
        return obs, reward, False, False, info

    def waypoint_controller(self, obs, info):
        """Jacobian pseudo-inverse toward info["waypoint"], reached in one step if the speed allows."""
        err = np.asarray(info["waypoint"]) - fk(self.q)
        qdot = np.linalg.pinv(jacobian(self.q)) @ (err / DT)
        a = qdot / QDOT_SCALE
        m = np.max(np.abs(a))
        if m > 1.0:
            a = a / m  # keep the direction, scale into the action box
        return a.astype(np.float32)


gym.register("Arm3-v0", entry_point=Arm3, max_episode_steps=T_MAX, reward_threshold=REWARD_THRESHOLD)
