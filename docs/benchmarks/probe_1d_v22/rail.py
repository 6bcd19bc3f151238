"""Rail-v0: a cart on a 1-D rail driven by a force (second order), to a random goal.

Dynamics (dt = 0.05 s, 120 steps = 6 s): m dv/dt = F - c v, m = 1 kg, c = 1 N s/m, F in [-2, 2] N
(terminal speed 2 m/s), semi-implicit Euler. The rail ends at +-2 m (the cart stops there, v = 0).
Start and goal uniform in [-1.5, 1.5] m, at least 0.5 m apart; the cart starts at rest.

Observation (4): x, v, goal, goal - x.
Reward: progress, 10 * (d_prev - d) / d0 with d = |goal - x| and d0 the start distance, so an episode
returns 10 * (1 - d_T / d0): 10 at the goal at the end, 0 for standing still, negative moving away.

Waypoints (spatial, 1-D): fixed points every 0.1 m on the start->goal segment (the last the goal);
info["waypoint"] is the first one not yet reached or passed (within 0.02 m, or behind the cart along
the start->goal direction), so a cart that overshoots is pointed back at the goal, never at a
waypoint left behind.
"""
import gymnasium as gym
import numpy as np

DT, MASS, DAMP, FMAX = 0.05, 1.0, 1.0, 2.0
X_MAX, SPACING, REACH = 2.0, 0.1, 0.02
MAX_STEPS = 120


class Rail(gym.Env):
    observation_space = gym.spaces.Box(-10.0, 10.0, (4,), np.float32)
    action_space = gym.spaces.Box(-FMAX, FMAX, (1,), np.float32)  # force, N

    def _waypoint(self):
        # advance past every waypoint reached or passed (projection on the start->goal direction)
        while self.k < len(self.wps) - 1 and (self.wps[self.k] - self.x) * self.dir <= REACH:
            self.k += 1
        return self.wps[self.k]

    def _obs_info(self):
        obs = np.array([self.x, self.v, self.goal, self.goal - self.x], np.float32)
        info = {"position": np.array([self.x]), "waypoint": np.array([self._waypoint()])}
        return obs, info

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        rng = self.np_random
        self.x = float(rng.uniform(-1.5, 1.5))
        self.goal = float(rng.uniform(-1.5, 1.5))
        while abs(self.goal - self.x) < 0.5:
            self.goal = float(rng.uniform(-1.5, 1.5))
        self.v = 0.0
        self.d0 = abs(self.goal - self.x)
        self.dir = float(np.sign(self.goal - self.x))
        n = int(np.ceil(self.d0 / SPACING))
        self.wps = self.x + self.dir * np.minimum(SPACING * np.arange(1, n + 1), self.d0)
        self.wps[-1] = self.goal
        self.k = 0
        return self._obs_info()

    def step(self, action):
        f = float(np.clip(np.asarray(action, dtype=np.float64).reshape(-1)[0], -FMAX, FMAX))
        d_prev = abs(self.goal - self.x)
        self.v += DT * (f - DAMP * self.v) / MASS
        self.x += DT * self.v
        if abs(self.x) > X_MAX:  # end stop
            self.x, self.v = float(np.clip(self.x, -X_MAX, X_MAX)), 0.0
        d = abs(self.goal - self.x)
        obs, info = self._obs_info()
        return obs, 10.0 * (d_prev - d) / self.d0, False, False, info

    def waypoint_controller(self, obs, info):
        """Follow the waypoints: a speed toward the next waypoint that shrinks near the goal
        (2 /s times the distance left, at most 1.8 m/s), tracked with feedforward of the damping."""
        w = float(info["waypoint"][0])
        direction = np.sign(w - self.x)
        v_des = direction * min(1.8, 3.0 * abs(self.goal - self.x))
        f = DAMP * v_des + MASS * 8.0 * (v_des - self.v)
        return np.array([np.clip(f, -FMAX, FMAX)], np.float32)


# reward_threshold 9.0 = 0.9 x the waypoint controller's mean return. Measured by stepping
# env.unwrapped.waypoint_controller on reset(seed=1000..1019) (20 episodes): controller 10.00 (+-0.00),
# zero action 0.00, uniform random actions 0.72 (+-5.1); `shaped-es check-env rail:Rail-v0` (10 episodes)
# agrees: 10.00 / 0.00 / -3.18 and 0.9 x = 9.00. Solved = the cart ends within 10% of the start distance.
gym.register("Rail-v0", entry_point=Rail, max_episode_steps=MAX_STEPS, reward_threshold=9.0)
