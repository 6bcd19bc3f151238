"""Edge-case variants of the README's MyPoint env, each changing ONE thing a user plausibly writes differently.

Usage: shaped-es check-env edge_envs:Edge-<name>-v0   (see REPORT.md for the list)
"""
import os
import time

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.wrappers import ClipAction, NormalizeObservation, RecordEpisodeStatistics, TimeLimit

F32 = np.float32


class Base(gym.Env):
    """README's MyPoint: a 2-D point steered toward waypoints on the way to a goal; 50 steps."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 30}
    observation_space = spaces.Box(-5.0, 5.0, (4,), F32)  # position, goal
    action_space = spaces.Box(-1.0, 1.0, (2,), F32)  # velocity

    def __init__(self, render_mode=None):
        self.render_mode = render_mode

    # --- hooks a variant overrides -------------------------------------------------
    def make_obs(self):
        return np.concatenate([self.pos, self.goal]).astype(F32)

    def velocity(self, action):
        return np.clip(np.asarray(action, dtype=float).reshape(2), -1.0, 1.0)

    def make_reward(self, r):
        return float(r)

    def make_info(self, pos, wp):
        return {"position": pos, "waypoint": wp}

    # ---------------------------------------------------------------------------------
    def _obs_info(self):
        d = self.goal - self.pos
        step = min(1.0, 0.1 / max(float(np.linalg.norm(d)), 1e-9))
        info = self.make_info(self.pos.copy(), self.pos + step * d)
        return self.make_obs(), info

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.t = 0
        self.pos = np.zeros(2)
        self.goal = self.np_random.uniform(-2.0, 2.0, 2)
        return self._obs_info()

    def step(self, action):
        self.t += 1
        self.pos = np.clip(self.pos + 0.1 * self.velocity(action), -5.0, 5.0)
        obs, info = self._obs_info()
        return obs, self.make_reward(-float(np.linalg.norm(self.goal - self.pos))), False, False, info

    def render(self):
        img = np.zeros((64, 64, 3), np.uint8)
        ij = np.clip(((self.pos + 5) / 10 * 63).astype(int), 0, 63)
        img[ij[1], ij[0]] = 255
        return img


# ---------------------------------------------------------------- observations
class ObsDictNested(Base):
    observation_space = spaces.Dict({
        "agent": spaces.Dict({"pos": spaces.Box(-5, 5, (2,), F32)}),
        "goal": spaces.Box(-5, 5, (2,), F32),
    })

    def make_obs(self):
        return {"agent": {"pos": self.pos.astype(F32)}, "goal": self.goal.astype(F32)}


class ObsDictTuple(Base):
    observation_space = spaces.Dict({
        "pos": spaces.Box(-5, 5, (2,), F32),
        "goal": spaces.Tuple((spaces.Box(-5, 5, (1,), F32), spaces.Box(-5, 5, (1,), F32))),
    })

    def make_obs(self):
        return {"pos": self.pos.astype(F32), "goal": (self.goal[:1].astype(F32), self.goal[1:].astype(F32))}


class ObsTuple(Base):
    observation_space = spaces.Tuple((spaces.Box(-5, 5, (2,), F32), spaces.Box(-5, 5, (2,), F32)))

    def make_obs(self):
        return (self.pos.astype(F32), self.goal.astype(F32))


class ObsBox23(Base):
    observation_space = spaces.Box(-5.0, 5.0, (2, 3), F32)  # rows x, y: pos, goal, goal-pos

    def make_obs(self):
        return np.stack([self.pos, self.goal, np.clip(self.goal - self.pos, -5, 5)], axis=1).astype(F32)


class ObsF64(Base):
    observation_space = spaces.Box(-5.0, 5.0, (4,), np.float64)

    def make_obs(self):
        return np.concatenate([self.pos, self.goal])


class ObsF64Mismatch(Base):
    """space says float32, obs returned as float64 (forgot .astype)."""

    def make_obs(self):
        return np.concatenate([self.pos, self.goal])


class ObsInf(Base):
    observation_space = spaces.Box(-np.inf, np.inf, (4,), F32)


class ObsOffset(Base):
    observation_space = spaces.Box(-np.inf, np.inf, (5,), F32)

    def make_obs(self):
        return np.concatenate([self.pos, self.goal, [1e4]]).astype(F32)


class ObsOffsetAll(Base):
    """positions reported in a frame offset by 1e4 (e.g. UTM-like coordinates)."""

    observation_space = spaces.Box(-np.inf, np.inf, (4,), F32)

    def make_obs(self):
        return (np.concatenate([self.pos, self.goal]) + 1e4).astype(F32)


# ---------------------------------------------------------------- actions
class Act21(Base):
    action_space = spaces.Box(-1.0, 1.0, (2, 1), F32)

    def velocity(self, action):
        assert np.shape(action) == (2, 1), np.shape(action)
        return np.clip(np.asarray(action, float)[:, 0], -1, 1)


class ActF64(Base):
    action_space = spaces.Box(-1.0, 1.0, (2,), np.float64)


class ActAsym(Base):
    """a0 in [0, 1] is a throttle along +x - 0.5 ... user maps both to velocities in [-1, 1]."""

    action_space = spaces.Box(np.array([0.0, -2.0], F32), np.array([1.0, 0.5], F32), dtype=F32)

    def velocity(self, action):
        a = np.asarray(action, float)
        return np.clip(np.array([2 * a[0] - 1.0, (a[1] + 0.75) / 1.25]), -1, 1)


class ActAsymRaw(Base):
    """asymmetric bounds used raw as velocity: zero action (the middle) is (0.5, -0.75)."""

    action_space = spaces.Box(np.array([0.0, -2.0], F32), np.array([1.0, 0.5], F32), dtype=F32)

    def velocity(self, action):
        return np.asarray(action, float)


class ActTiny(Base):
    action_space = spaces.Box(-0.01, 0.01, (2,), F32)

    def velocity(self, action):
        return np.clip(np.asarray(action, float) * 100.0, -1, 1)


class Act1(Base):
    """a 1-D point on a line: action (1,), position and waypoint (1,)."""

    observation_space = spaces.Box(-5.0, 5.0, (2,), F32)
    action_space = spaces.Box(-1.0, 1.0, (1,), F32)

    def reset(self, *, seed=None, options=None):
        super(Base, self).reset(seed=seed)
        self.t = 0
        self.pos = np.zeros(1)
        self.goal = self.np_random.uniform(-2.0, 2.0, 1)
        return self._obs_info()

    def make_obs(self):
        return np.concatenate([self.pos, self.goal]).astype(F32)

    def velocity(self, action):
        return np.clip(np.asarray(action, float).reshape(1), -1, 1)


class ActAssertContains(Base):
    """a strict user: asserts the action is in the space (Box.contains checks dtype castability)."""

    def step(self, action):
        assert self.action_space.contains(action), f"bad action {action!r}"
        return super().step(action)


# ---------------------------------------------------------------- rewards
class RewF32(Base):
    def make_reward(self, r):
        return np.float32(r)


class Rew0d(Base):
    def make_reward(self, r):
        return np.array(r)


class RewInt(Base):
    def make_reward(self, r):
        return int(round(10 * r))


class Rew1(Base):
    """reward as a shape-(1,) array (e.g. from a matrix expression)."""

    def make_reward(self, r):
        return np.array([r])


class RewNaNSometimes(Base):
    """distance computed with a division that gives NaN at the goal's exact ... here: NaN when the goal x > 1.9."""

    def make_reward(self, r):
        bad = self.goal[0] > 1.9 and self.t == 10 and not os.environ.get("EDGE_FIXED")
        return float("nan") if bad else float(r)


# ---------------------------------------------------------------- info
class InfoList(Base):
    def make_info(self, pos, wp):
        return {"position": pos.tolist(), "waypoint": wp.tolist()}


class InfoTuple(Base):
    def make_info(self, pos, wp):
        return {"position": tuple(pos), "waypoint": tuple(wp)}


class InfoF32(Base):
    def make_info(self, pos, wp):
        return {"position": pos.astype(F32), "waypoint": wp.astype(F32)}


class Info12(Base):
    def make_info(self, pos, wp):
        return {"position": pos.reshape(1, 2), "waypoint": wp.reshape(1, 2)}


class InfoPos12Only(Base):
    """position (1, 2), waypoint (2,): a user who keeps position as a row vector."""

    def make_info(self, pos, wp):
        return {"position": pos.reshape(1, 2), "waypoint": wp}


class InfoShapeMismatch(Base):
    """position (3,) (x, y, heading), waypoint (2,)."""

    def make_info(self, pos, wp):
        return {"position": np.append(pos, 0.0), "waypoint": wp}


class InfoNoWpAtReset(Base):
    def reset(self, *, seed=None, options=None):
        obs, info = super().reset(seed=seed, options=options)
        del info["waypoint"]
        return obs, info


class InfoEmptyReset(Base):
    """reset returns {} as info (the gymnasium template's default)."""

    def reset(self, *, seed=None, options=None):
        obs, _ = super().reset(seed=seed, options=options)
        return obs, {}


class InfoStaticPos(Base):
    """position stuck: the user reports the start position (copy made once)."""

    def reset(self, *, seed=None, options=None):
        obs, info = super().reset(seed=seed, options=options)
        self._p0 = info["position"]
        return obs, info

    def make_info(self, pos, wp):
        return {"position": getattr(self, "_p0", pos), "waypoint": wp}


class InfoAliasPos(Base):
    """position returned WITHOUT .copy(), and pos updated in place: every recorded position is the same array."""

    def step(self, action):
        self.t += 1
        self.pos += 0.1 * self.velocity(action)
        np.clip(self.pos, -5, 5, out=self.pos)
        d = self.goal - self.pos
        step = min(1.0, 0.1 / max(float(np.linalg.norm(d)), 1e-9))
        info = {"position": self.pos, "waypoint": self.pos + step * d}
        return self.make_obs(), -float(np.linalg.norm(d)), False, False, info

    def reset(self, *, seed=None, options=None):
        obs, info = super().reset(seed=seed, options=options)
        info["position"] = self.pos
        return obs, info


class _Seq(Base):
    """Discrete waypoints every 0.25 on the start-goal line, consumed when reached or passed; after the
    last one is consumed the episode goes on (the point should hold at the goal)."""

    after = "none"

    def reset(self, *, seed=None, options=None):
        super(Base, self).reset(seed=seed)
        self.t = 0
        self.pos = np.zeros(2)
        self.goal = self.np_random.uniform(-2.0, 2.0, 2)
        n = max(1, int(np.ceil(np.linalg.norm(self.goal) / 0.25)))
        self.wps = [self.goal * (k / n) for k in range(1, n + 1)]
        self.k = 0
        return self._obs_info()

    def _obs_info(self):
        u = self.goal / max(np.linalg.norm(self.goal), 1e-9)
        while self.k < len(self.wps) and (np.linalg.norm(self.wps[self.k] - self.pos) < 0.1
                                          or (self.pos @ u) >= (self.wps[self.k] @ u)):
            self.k += 1
        if self.k < len(self.wps):
            wp = self.wps[self.k].copy()
        elif self.after == "none":
            wp = None
        elif self.after == "nan":
            wp = np.full(2, np.nan)
        elif self.after == "absent":
            return self.make_obs(), {"position": self.pos.copy()}
        else:  # hold the goal (the right thing)
            wp = self.goal.copy()
        return self.make_obs(), {"position": self.pos.copy(), "waypoint": wp}


class SeqHold(_Seq):
    after = "hold"


class SeqNone(_Seq):
    after = "none"


class SeqNaN(_Seq):
    after = "nan"


class SeqAbsent(_Seq):
    after = "absent"


class TermFirst(Base):
    """terminates on its very first step (e.g. spawn in collision) for some goals; else as Base."""

    def step(self, action):
        obs, r, term, trunc, info = super().step(action)
        return obs, r, bool(self.goal[0] > 0.0 and self.t == 1) or term, trunc, info


class TermFirstAlways(Base):
    def step(self, action):
        obs, r, term, trunc, info = super().step(action)
        return obs, r, True, trunc, info


class TermAtGoal(Base):
    """ends the episode at the goal (README advice), with a +10 bonus."""

    def step(self, action):
        obs, r, term, trunc, info = super().step(action)
        done = np.linalg.norm(self.goal - self.pos) < 0.1
        return obs, r + (10.0 if done else 0.0), bool(done), trunc, info


# ---------------------------------------------------------------- construction
class NeedsKwarg(Base):
    def __init__(self, speed, render_mode=None):
        super().__init__(render_mode)
        self.speed = float(speed)

    def velocity(self, action):
        return super().velocity(action) * self.speed / 0.1 * 0.1


class NeedsRenderMode(Base):
    def __init__(self, render_mode):
        assert render_mode in self.metadata["render_modes"], f"render_mode required, got {render_mode!r}"
        super().__init__(render_mode)


class Seedless(Base):
    """reset ignores `seed`, uses NumPy's global RNG."""

    def reset(self, *, seed=None, options=None):
        self.t = 0
        self.pos = np.zeros(2)
        self.goal = np.random.uniform(-2.0, 2.0, 2)
        return self._obs_info()


class SeedNoSuper(Base):
    """uses self.np_random but forgets super().reset(seed=seed): seeded once, randomly."""

    def reset(self, *, seed=None, options=None):
        self.t = 0
        self.pos = np.zeros(2)
        self.goal = self.np_random.uniform(-2.0, 2.0, 2)
        return self._obs_info()


class RaiseAt50(Base):
    def step(self, action):
        out = super().step(action)
        if self.t == 50 and self.goal[0] > 1.0 and not os.environ.get("EDGE_FIXED"):
            raise RuntimeError("simulator diverged at step 50")
        return out


class Slow(Base):
    def step(self, action):
        time.sleep(0.01)
        return super().step(action)


# ---------------------------------------------------------------- registration
def _reg(name, entry, **kw):
    kw.setdefault("max_episode_steps", 50)
    gym.register(f"Edge-{name}-v0", entry_point=entry, **kw)


_reg("Base", Base)
for _n, _c in [("ObsDictNested", ObsDictNested), ("ObsDictTuple", ObsDictTuple), ("ObsTuple", ObsTuple),
               ("ObsBox23", ObsBox23), ("ObsF64", ObsF64), ("ObsF64Mismatch", ObsF64Mismatch),
               ("ObsInf", ObsInf), ("ObsOffset", ObsOffset), ("ObsOffsetAll", ObsOffsetAll),
               ("Act21", Act21), ("ActF64", ActF64), ("ActAsym", ActAsym), ("ActAsymRaw", ActAsymRaw),
               ("ActTiny", ActTiny), ("Act1", Act1), ("ActAssertContains", ActAssertContains),
               ("RewF32", RewF32), ("Rew0d", Rew0d), ("RewInt", RewInt), ("Rew1", Rew1),
               ("RewNaNSometimes", RewNaNSometimes),
               ("InfoList", InfoList), ("InfoTuple", InfoTuple), ("InfoF32", InfoF32), ("Info12", Info12),
               ("InfoPos12Only", InfoPos12Only), ("InfoShapeMismatch", InfoShapeMismatch),
               ("InfoNoWpAtReset", InfoNoWpAtReset), ("InfoEmptyReset", InfoEmptyReset),
               ("InfoStaticPos", InfoStaticPos), ("InfoAliasPos", InfoAliasPos),
               ("SeqHold", SeqHold), ("SeqNone", SeqNone), ("SeqNaN", SeqNaN), ("SeqAbsent", SeqAbsent),
               ("TermFirst", TermFirst), ("TermFirstAlways", TermFirstAlways), ("TermAtGoal", TermAtGoal),
               ("NeedsKwarg", NeedsKwarg), ("NeedsRenderMode", NeedsRenderMode),
               ("Seedless", Seedless), ("SeedNoSuper", SeedNoSuper), ("Slow", Slow)]:
    _reg(_n, _c)
_reg("RaiseAt50", RaiseAt50, max_episode_steps=100)

# no time limit at all
gym.register("Edge-NoTimeLimit-v0", entry_point=Base)
# time limit by a wrapper in an entry-point function instead of max_episode_steps
gym.register("Edge-WrapTimeLimitFn-v0", entry_point=lambda **kw: TimeLimit(Base(**kw), 50))
# wrappers at registration (gymnasium applies them in make via additional_wrappers is internal; users use fn)
gym.register("Edge-WrapRecordStats-v0", entry_point=lambda **kw: RecordEpisodeStatistics(Base(**kw)),
             max_episode_steps=50)
gym.register("Edge-WrapNormObs-v0", entry_point=lambda **kw: NormalizeObservation(Base(**kw)),
             max_episode_steps=50)
gym.register("Edge-WrapClipAction-v0", entry_point=lambda **kw: ClipAction(ActAsymRaw(**kw)),
             max_episode_steps=50)
# entry point as a "module:Class" string, the usual gymnasium style
gym.register("Edge-StringEntry-v0", entry_point="edge_envs:Base", max_episode_steps=50)


# ---------------------------------------------------------------- batch 2
class ActDiscrete(Base):
    """5 actions: stay, +x, -x, +y, -y (0 = stay: the README's no-op advice)."""

    action_space = spaces.Discrete(5)
    _V = np.array([[0, 0], [1, 0], [-1, 0], [0, 1], [0, -1]], float)

    def velocity(self, action):
        return self._V[int(action)]


class GridInt(Base):
    """a grid world: integer positions (np.int64) and waypoints, Discrete(5) moves of one cell."""

    observation_space = spaces.Box(-20, 20, (4,), np.float32)
    action_space = spaces.Discrete(5)
    _V = np.array([[0, 0], [1, 0], [-1, 0], [0, 1], [0, -1]], np.int64)

    def reset(self, *, seed=None, options=None):
        super(Base, self).reset(seed=seed)
        self.t = 0
        self.pos = np.zeros(2, np.int64)
        self.goal = self.np_random.integers(-8, 9, 2)
        return self._obs_info()

    def _obs_info(self):
        d = self.goal - self.pos
        wp = self.pos + np.sign(d) * (np.abs(d) == np.abs(d).max())  # one cell along the longer axis
        obs = np.concatenate([self.pos, self.goal]).astype(np.float32) / 10
        return obs, {"position": self.pos.copy(), "waypoint": wp.astype(np.int64)}

    def step(self, action):
        self.t += 1
        self.pos = np.clip(self.pos + self._V[int(action)], -20, 20)
        obs, info = self._obs_info()
        return obs, -float(np.abs(self.goal - self.pos).sum()), False, False, info


class ObsList(Base):
    """observation returned as a Python list."""

    def make_obs(self):
        return [float(v) for v in np.concatenate([self.pos, self.goal])]


class InfoScalar1D(Act1):
    """1-D body reporting position/waypoint as Python floats (not arrays)."""

    def make_info(self, pos, wp):
        return {"position": float(pos[0]), "waypoint": float(wp[0])}


class WpRelative(Base):
    """user gives the waypoint RELATIVE to the agent (w - p) instead of absolute, against the contract."""

    def make_info(self, pos, wp):
        return {"position": pos, "waypoint": wp - pos}


for _n, _c in [("ActDiscrete", ActDiscrete), ("GridInt", GridInt), ("ObsList", ObsList),
               ("InfoScalar1D", InfoScalar1D), ("WpRelative", WpRelative)]:
    _reg(_n, _c)


# ---------------------------------------------------------------- batch 3
class ObsShapeChange(Base):
    """a sensor that drops out: obs of 3 values instead of 4 when the goal's x > 1.5, after step 20."""

    def make_obs(self):
        o = np.concatenate([self.pos, self.goal]).astype(F32)
        return o[:3] if (getattr(self, "t", 0) > 20 and self.goal[0] > 1.5) else o


class ObsDictDiscrete(Base):
    """Dict with a Discrete 'quadrant' of the goal (one-hot when flattened)."""

    observation_space = spaces.Dict({"pos": spaces.Box(-5, 5, (2,), F32), "goal": spaces.Box(-5, 5, (2,), F32),
                                     "quadrant": spaces.Discrete(4)})

    def make_obs(self):
        q = int(self.goal[0] > 0) + 2 * int(self.goal[1] > 0)
        return {"pos": self.pos.astype(F32), "goal": self.goal.astype(F32), "quadrant": q}


class ActMultiDiscrete(Base):
    """x and y each in {stay, +, -}."""

    action_space = spaces.MultiDiscrete([3, 3])

    def velocity(self, action):
        m = np.array([0.0, 1.0, -1.0])
        return m[np.asarray(action, int)]


for _n, _c in [("ObsShapeChange", ObsShapeChange), ("ObsDictDiscrete", ObsDictDiscrete),
               ("ActMultiDiscrete", ActMultiDiscrete)]:
    _reg(_n, _c)
