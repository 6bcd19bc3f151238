"""A self-balancing two-wheeled robot (cart-pole on a line, Segway-like) that must drive to a goal.

State x, x_dot, theta (pole angle from vertical, rad), theta_dot. Action: wheel force in [-1, 1],
scaled to 10 N. Standard cart-pole dynamics (Gymnasium CartPole's equations: g 9.8, cart 1 kg,
pole 0.1 kg, pole half-length 0.5 m, dt 0.02 s, explicit Euler). 300 steps; terminated if
|theta| > 0.5 rad or |x| > 6.

Per episode: start x ~ U[-0.5, 0.5], small random x_dot/theta/theta_dot (+-0.05), goal x ~ U[-3, 3]
with |goal - start| >= 1.5. 1-D spatial waypoints every 0.25 m from the start toward the goal (the
last one is the goal), consumed when reached (within 0.05 m) or passed.

Observation (6): x, x_dot, theta, theta_dot, goal - x, next waypoint - x.
info: position = [x], waypoint = [next waypoint x].

Reward per step:
  +0.01 alive bonus
  + progress: the decrease of the distance to the current waypoint over the step (all waypoints lie
    on the start-goal segment, so this is the decrease of the distance to the goal; 1 per metre;
    summed over an episode it is the net distance gained, 1.5-3.5 when the goal is reached)
  + 2.0 once, the first time |x - goal| < 0.15 m
  - 2.0 if the episode terminates (pole fell or cart left the track)
So: balancing in place for 300 steps ~ 3.0; balancing and reaching the goal ~ 3.0 + 1.5..3.5 + 2
= 6.5..8.5 (mean ~7.4); reaching the goal and then falling loses the bonus back.

Threshold 6.6 = 0.9 x the waypoint controller's mean (7.40 over 30 seeds, reaches 30/30, never falls).
An episode that balances but misses the goal scores at most ~3 + distance (no +2), one that reaches it
3 + distance + 2; with a mean distance ~2.4, a 15-episode mean of 6.6 needs the goal reached on at least
~60% of episodes even if the misses got almost there (and every episode balanced: a fall costs 2 plus
the lost alive bonus). Balancing in place gives 3.0, so it can never pass.
"""
import gymnasium as gym
import numpy as np

GRAVITY, M_CART, M_POLE, HALF_LEN, DT, FORCE = 9.8, 1.0, 0.1, 0.5, 0.02, 10.0
TOTAL = M_CART + M_POLE
PML = M_POLE * HALF_LEN
SPACING, REACH, GOAL_R = 0.25, 0.05, 0.15
MAX_STEPS = 300


def _dynamics(s, force):
    x, xd, th, thd = s
    c, si = np.cos(th), np.sin(th)
    temp = (force + PML * thd * thd * si) / TOTAL
    thacc = (GRAVITY * si - c * temp) / (HALF_LEN * (4.0 / 3.0 - M_POLE * c * c / TOTAL))
    xacc = temp - PML * thacc * c / TOTAL
    return np.array([x + DT * xd, xd + DT * xacc, th + DT * thd, thd + DT * thacc])


def _lqr_gain():
    """Discrete LQR on the Euler-discretised linearisation at the upright, force input (N)."""
    from scipy.linalg import solve_discrete_are

    eps = 1e-6
    s0 = np.zeros(4)
    A = np.zeros((4, 4))
    for i in range(4):
        d = np.zeros(4)
        d[i] = eps
        A[:, i] = (_dynamics(s0 + d, 0.0) - _dynamics(s0 - d, 0.0)) / (2 * eps)
    B = ((_dynamics(s0, eps) - _dynamics(s0, -eps)) / (2 * eps)).reshape(4, 1)
    Q = np.diag([5.0, 1.0, 10.0, 1.0])
    R = np.array([[0.1]])
    P = solve_discrete_are(A, B, Q, R)
    return np.linalg.solve(R + B.T @ P @ B, B.T @ P @ A).ravel()


_K = None


class Segway(gym.Env):
    observation_space = gym.spaces.Box(-np.inf, np.inf, (6,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (1,), np.float32)

    def _obs_info(self):
        x = self.s[0]
        wp = self.wps[self.k]
        obs = np.array([*self.s, self.goal - x, wp - x], dtype=np.float32)
        return obs, {"position": np.array([x]), "waypoint": np.array([wp])}

    def _advance(self):
        x = self.s[0]
        while self.k < len(self.wps) - 1 and self.sign * (x - self.wps[self.k]) >= -REACH:
            self.k += 1

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        r = self.np_random
        self.s = r.uniform(-0.05, 0.05, 4)
        self.s[0] = r.uniform(-0.5, 0.5)
        while True:
            self.goal = r.uniform(-3.0, 3.0)
            if abs(self.goal - self.s[0]) >= 1.5:
                break
        dist = abs(self.goal - self.s[0])
        self.sign = np.sign(self.goal - self.s[0])
        n = int(np.ceil(dist / SPACING - 1e-9))
        self.wps = self.s[0] + self.sign * np.minimum(SPACING * np.arange(1, n + 1), dist)
        self.k = 0
        self.t = 0
        self.reached = False
        self._advance()
        return self._obs_info()

    def step(self, action):
        a = float(np.clip(np.asarray(action, dtype=np.float64).ravel()[0], -1.0, 1.0))
        d_prev = abs(self.goal - self.s[0])
        self.s = _dynamics(self.s, FORCE * a)
        self.t += 1
        x, th = self.s[0], self.s[2]
        reward = 0.01 + (d_prev - abs(self.goal - x))
        if not self.reached and abs(x - self.goal) < GOAL_R:
            self.reached = True
            reward += 2.0
        terminated = bool(abs(th) > 0.5 or abs(x) > 6.0)
        if terminated:
            reward -= 2.0
        self._advance()
        obs, info = self._obs_info()
        info["reached_goal"] = self.reached
        return obs, float(reward), terminated, False, info

    def waypoint_controller(self, obs, info):
        """LQR balance that tracks a reference 1.0 m beyond the body toward the next waypoint
        (capped at the goal): the pole leans toward the waypoint and the cart follows."""
        global _K
        if _K is None:
            _K = _lqr_gain()
        x, xd, th, thd = (float(v) for v in obs[:4])
        wp = float(np.asarray(info["waypoint"]).ravel()[0])
        goal = x + float(obs[4])
        d = wp - x
        ref = x + np.sign(d) * min(1.0, abs(goal - x)) if abs(d) > 1e-9 else wp
        u = -_K @ np.array([x - ref, xd, th, thd])
        return np.array([np.clip(u / FORCE, -1.0, 1.0)], dtype=np.float32)


gym.register("Segway-v0", entry_point=Segway, max_episode_steps=MAX_STEPS, reward_threshold=6.6)
