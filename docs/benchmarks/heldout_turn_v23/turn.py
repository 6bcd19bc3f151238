"""Turn: a torque-driven turntable that must turn to a goal heading through heading waypoints.

Body: a rotating body without gravity (a motorised turntable).
    omega <- omega + dt * (GAIN * u - DAMPING * omega),   theta <- theta + dt * omega
    u in [-1, 1] (torque), dt = 0.05, GAIN = 4 rad/s^2, DAMPING = 1 /s (top speed 4 rad/s).
Episode: 100 steps (5 s). Start heading and goal heading uniform on the circle, independently, so the
short way from start to goal is up to half a turn and crosses +-pi in about a quarter of the episodes.

Waypoints (spatial): headings every 0.1 rad along the short way from the start to the goal (the last one
is the goal). A waypoint is consumed when the body has reached it or passed it along that direction
(progress measured on the unwrapped heading), within a tolerance of 0.05 rad.

Observation (7): cos th, sin th, cos goal, sin goal, sin e, cos e, omega / 4, with e = wrap(goal - th)
(the short-way heading error).

Reward (dense, as the README's MyPoint example): r_t = -|e_t|, the short-way heading error in rad after the
step (no torque cost). Zero action returns -100 x |e_0| (about -157 on average), a fast turn much less.

info["position"] / info["waypoint"] (what the waypoints are about), the only difference between ids:
    Turn-v0: the wrapped heading in (-pi, pi], shape (1,)          (a new user's first choice)
    Turn-v1: the point (cos th, sin th) on the unit circle, shape (2,)
    TurnUnwrapped-v0: the unwrapped heading (continuous, no jump), shape (1,): a control for v0
    (named apart so that Gymnasium does not call Turn-v0 "out of date")

waypoint_controller: a PD controller toward the waypoint heading along the short way.
Threshold: see reward_threshold below and README.md (90% of the way from zero action's return to the
controller's, as check-env's controller line suggests).
"""
import gymnasium as gym
import numpy as np

DT = 0.05
GAIN = 4.0
DAMPING = 1.0
SPACING = 0.1
TOL = 0.05
T = 100
KP = 20.0
KD = 1.0


def wrap(a):
    """Wrap to (-pi, pi]."""
    a = np.mod(a + np.pi, 2 * np.pi) - np.pi
    return np.where(a == -np.pi, np.pi, a)


class Turn(gym.Env):
    observation_space = gym.spaces.Box(-np.inf, np.inf, (7,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (1,), np.float32)
    metadata = {"render_modes": []}

    def __init__(self, position="wrapped"):
        assert position in ("wrapped", "circle", "unwrapped")
        self.position_kind = position

    # --- helpers -------------------------------------------------------------------------------
    def _heading(self):
        return float(wrap(self.theta_u))

    def _err(self):
        return float(wrap(self.goal - self.theta_u))

    def _report(self, angle_unwrapped):
        if self.position_kind == "wrapped":
            return np.array([float(wrap(angle_unwrapped))])
        if self.position_kind == "unwrapped":
            return np.array([float(angle_unwrapped)])
        return np.array([np.cos(angle_unwrapped), np.sin(angle_unwrapped)])

    def _advance(self):
        progress = self.dir * (self.theta_u - self.start)
        while self.k < len(self.wps) - 1 and self.dir * (self.wps[self.k] - self.start) <= progress + TOL:
            self.k += 1
        if self.k == len(self.wps) - 1 and self.dir * (self.wps[self.k] - self.start) <= progress + TOL:
            pass  # the goal stays the waypoint once reached

    def _obs_info(self):
        th = self.theta_u
        e = self._err()
        obs = np.array([np.cos(th), np.sin(th), np.cos(self.goal), np.sin(self.goal),
                        np.sin(e), np.cos(e), self.omega / 4.0], dtype=np.float32)
        info = {"position": self._report(th), "waypoint": self._report(self.wps[self.k]),
                "heading": self._heading(), "heading_error": e}
        return obs, info

    # --- gym API -------------------------------------------------------------------------------
    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.start = float(self.np_random.uniform(-np.pi, np.pi))
        self.goal = float(self.np_random.uniform(-np.pi, np.pi))
        self.theta_u = self.start  # unwrapped heading, starts wrapped
        self.omega = 0.0
        delta = float(wrap(self.goal - self.start))  # short way
        self.dir = 1.0 if delta >= 0 else -1.0
        n = max(1, int(np.ceil(abs(delta) / SPACING)))
        self.wps = [self.start + self.dir * min(SPACING * (i + 1), abs(delta)) for i in range(n)]  # unwrapped
        self.k = 0
        self._advance()
        return self._obs_info()

    def step(self, action):
        u = float(np.clip(np.asarray(action, dtype=np.float64).reshape(-1)[0], -1.0, 1.0))
        self.omega += DT * (GAIN * u - DAMPING * self.omega)
        self.theta_u += DT * self.omega
        self._advance()
        reward = -abs(self._err())
        obs, info = self._obs_info()
        return obs, float(reward), False, False, info

    def waypoint_controller(self, obs, info):
        """PD toward the next waypoint heading along the short way (reads the env's own state)."""
        e = float(wrap(self.wps[self.k] - self.theta_u))
        return np.array([np.clip(KP * e - KD * self.omega, -1.0, 1.0)], dtype=np.float32)


THRESHOLD = -45.0  # check-env's controller line: -45.65 (90% of the way from zero action -166.62 to the controller -32.21, seeds 0-9)

for _id, _kind in (("Turn-v0", "wrapped"), ("Turn-v1", "circle"), ("TurnUnwrapped-v0", "unwrapped")):
    if _id not in gym.registry:
        gym.register(_id, entry_point=Turn, kwargs={"position": _kind}, max_episode_steps=T,
                     reward_threshold=THRESHOLD)
