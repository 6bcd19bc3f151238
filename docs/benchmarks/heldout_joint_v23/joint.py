"""A planar 2-link arm with continuous (wrapping) revolute joints, waypoints in joint space.

Pure numpy. Registers on import:
  JointArm-v0          info["position"] / info["waypoint"] wrapped into (-pi, pi]; no declaration
                       (shaped-es should detect the wrap)
  JointArmDeclared-v0  the same, with env.position_period = 2 pi declared (README "Angles that wrap")
  JointArmOff-v0       the same, with env.position_period = None: "nothing wraps" (the control arm)
Scratch ids with wrong declarations (for the error messages): JointArmBadStr-v0, JointArmBad3-v0,
JointArmBadNeg-v0, JointArmBadNan-v0.

Body: joint angles q (2), unwrapped internally, velocities qd; qdd = k * u - c * qd (k = (3, 5): a heavier
shoulder, a lighter elbow; c = 1), semi-implicit Euler with dt = 0.05, torques u in [-1, 1]^2, 100 steps.
Task: from a random start configuration to a random goal configuration, each joint the short way (so about
44% of episodes cross +-pi on at least one joint). Waypoints: spatial, every 0.1 rad (joint-space norm) on the
straight line in joint space from the start to the short-way goal; a waypoint is consumed once the arm's
projection on that line has passed it or it is within 0.05 rad. Reward: minus the short-way joint-space
distance to the goal, ||wrap(goal - q)||, per step.
Observation (12): cos q, sin q, cos goal, sin goal, wrap(goal - q) / pi, qd / 4.
"""

import gymnasium as gym
import numpy as np

TWO_PI = 2.0 * np.pi
_UNSET = object()


def wrap(x):
    """Into (-pi, pi] (what an encoder reports)."""
    return np.pi - np.mod(np.pi - np.asarray(x, dtype=np.float64), TWO_PI)


class JointArm(gym.Env):
    metadata = {"render_modes": []}

    observation_space = gym.spaces.Box(-2.0, 2.0, (12,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)

    dt = 0.05
    gain = np.array([3.0, 5.0])
    damping = 1.0
    spacing = 0.1
    reach_radius = 0.05

    def __init__(self, position_period=_UNSET, start_half_width=np.pi, damping=1.0):
        self.damping = damping
        self.start_half_width = start_half_width  # scratch variant: starts near 0 (random actions rarely cross +-pi)
        if position_period is not _UNSET:
            self.position_period = position_period  # the README's declaration

    # -- internals -------------------------------------------------------------------------------
    def _waypoint(self, i):
        s = min(i * self.spacing, self.length)
        return self.q0 + s * self.direction

    def _advance(self):
        s = float(np.dot(self.q - self.q0, self.direction))  # progress along the start-goal line
        while self.idx < self.n_wp:
            w = self._waypoint(self.idx)
            if s >= min(self.idx * self.spacing, self.length) or np.linalg.norm(self.q - w) < self.reach_radius:
                self.idx += 1
            else:
                break

    def _next_waypoint(self):
        return self._waypoint(min(self.idx, self.n_wp))  # the goal once every waypoint is consumed

    def _obs_info(self):
        e = wrap(self.goal - self.q)
        obs = np.concatenate([np.cos(self.q), np.sin(self.q), np.cos(self.goal), np.sin(self.goal),
                              e / np.pi, self.qd / 4.0]).astype(np.float32)
        info = {"position": wrap(self.q), "waypoint": wrap(self._next_waypoint())}
        return obs, info

    # -- Gymnasium ---------------------------------------------------------------------------------
    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.q0 = self.np_random.uniform(-self.start_half_width, self.start_half_width, 2)
        self.goal = self.np_random.uniform(-np.pi, np.pi, 2)
        self.q = self.q0.copy()
        self.qd = np.zeros(2)
        e0 = wrap(self.goal - self.q0)  # the short way, per joint
        self.length = float(np.linalg.norm(e0))
        self.direction = e0 / max(self.length, 1e-9)
        self.n_wp = max(1, int(np.ceil(self.length / self.spacing)))
        self.idx = 1
        self._advance()
        return self._obs_info()

    def step(self, action):
        u = np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0)
        self.qd = self.qd + self.dt * (self.gain * u - self.damping * self.qd)
        self.q = self.q + self.dt * self.qd  # unwrapped, continuous joints: no limits
        self._advance()
        obs, info = self._obs_info()
        reward = -float(np.linalg.norm(wrap(self.goal - self.q)))
        return obs, reward, False, False, info

    # -- the oracle label source -------------------------------------------------------------------
    def waypoint_controller(self, obs, info):
        """PD toward the next waypoint, the short way on each joint."""
        w = self._next_waypoint()
        u = 30.0 * wrap(w - self.q) - 1.0 * self.qd
        return np.clip(u, -1.0, 1.0).astype(np.float32)


# threshold: check-env's controller line, -71.99 rounded (90% of the way from zero action to the controller)
_kw = dict(entry_point=JointArm, max_episode_steps=100, reward_threshold=-72.0)
gym.register("JointArm-v0", **_kw)
gym.register("JointArmDeclared-v0", kwargs={"position_period": TWO_PI}, **_kw)
gym.register("JointArmOff-v0", kwargs={"position_period": None}, **_kw)
# scratch: wrong declarations
gym.register("JointArmBadStr-v0", kwargs={"position_period": "2pi"}, **_kw)
gym.register("JointArmBad3-v0", kwargs={"position_period": (TWO_PI, TWO_PI, TWO_PI)}, **_kw)
gym.register("JointArmBadNeg-v0", kwargs={"position_period": -1.0}, **_kw)
gym.register("JointArmBadNan-v0", kwargs={"position_period": float("nan")}, **_kw)
# scratch: valid-looking but questionable declarations
gym.register("JointArmDeg-v0", kwargs={"position_period": 360.0}, **_kw)  # degrees, on a radian body
gym.register("JointArmZero-v0", kwargs={"position_period": 0}, **_kw)
gym.register("JointArmArray-v0", kwargs={"position_period": np.array([TWO_PI, TWO_PI])}, **_kw)
gym.register("JointArmMixed-v0", kwargs={"position_period": [TWO_PI, None]}, **_kw)  # elbow "not wrapping"
gym.register("JointArmNarrow-v0", kwargs={"start_half_width": 1.0}, **_kw)  # wrap detection with few crossings
gym.register("JointArmStill-v0", kwargs={"start_half_width": 0.3, "damping": 4.0}, **_kw)  # random actions never cross
