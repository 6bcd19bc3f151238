"""The inverse-dynamics model ``M_phi(s_t, w_t) -> a_t`` of the paper (Lekkala & Itti, Sec. III).

``M_phi`` answers "which action moves the agent from ``s_t`` towards this point of waypoint space?". Its
input is the state concatenated with a *displacement* in waypoint space:

- training pairs (from rollouts): ``(s_t, position_{t+1} - position_t) -> a_t`` (what the agent did);
- queries (labelling, Eq. L(theta)): ``(s_t, waypoint_t - position_t) -> a_hat_t`` (what it should do).

Both are formed from recorded steps in ``mphi_inputs.py`` (frames, targets, the return filter, query
mixing and scaling); this module holds the model: its data set, training, labelling and state.

Paper settings (experiments section): MLP, 2 hidden layers of 20 with ReLU (navigation; the arm adds one
more layer), Adam lr 1e-3, batch 64; the master trains it on all workers' trajectories, aggregated over
generations; trajectories (episodes) whose cumulative reward is below 5 are discarded. The output is
squashed by ``tanh`` to ``[-1, 1]`` like the policy's actions. Inputs are standardized by running
mean/std statistics fitted from the data and stored with the model. The network and its Adam are the
lean NumPy ones of ``lean_mlp.py`` (3-5x faster per step than torch at this size).

Threading: :meth:`InverseDynamics.train` may run in a background thread while the master waits for the
workers (as in the paper). All state is held by the instance (own NumPy generator, own lock); the
model is never touched by global RNGs. For reproducible labels, ship ``state_dict(with_training=False)``
taken *before* ``train`` starts.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from shaped_es.data import Transitions
from shaped_es.shaping import kernels
from shaped_es.shaping.frames import frame_dim
from shaped_es.shaping.lean_mlp import FlatAdam, LeanMLP
from shaped_es.shaping.mphi_inputs import (  # noqa: F401 - the input helpers stay importable from here
    clip_norm,
    episode_end,
    query_change,
    query_inputs,
    kept_episodes,
    mixed_query,
    query_displacement,
    target_pairs,
    training_pairs,
)
from shaped_es.shaping.settings import InverseDynamicsConfig

LABEL_CHUNK = 4096  # rows per forward pass when labelling


class RunningNorm:
    """Running mean / variance of inputs (Chan et al. parallel update), as explicit float64 arrays.

    Kept instead of SB3's ``RunningMeanStd`` (the same update): ours caches the float32 shift/scale that
    labelling ~80k rows a generation applies (4-5x faster than a float64 normalize, measured) and leaves constant
    features unscaled instead of dividing by ``sqrt(var + eps)``."""

    def __init__(self, dim: int):
        self.count = 0.0
        self.mean = np.zeros(dim)  # (dim,)
        self.m2 = np.zeros(dim)  # (dim,) sum of squared deviations

    def update(self, x: np.ndarray) -> None:
        if x.shape[0] == 0:
            return
        if kernels.ENABLED and x.dtype == np.float32 and x.ndim == 2:  # one compiled pass, no float64 copy
            n_b, (mean_b, m2_b) = x.shape[0], kernels.column_stats(np.ascontiguousarray(x))
        else:
            x = x.astype(np.float64)
            n_b, mean_b = x.shape[0], x.mean(axis=0)
            m2_b = ((x - mean_b) ** 2).sum(axis=0)
        n = self.count + n_b
        delta = mean_b - self.mean
        self.mean = self.mean + delta * n_b / n
        self.m2 = self.m2 + m2_b + delta**2 * self.count * n_b / n
        self.count = n

    def std(self) -> np.ndarray:
        var = self.m2 / max(self.count, 1.0)
        return np.where(var > 1e-12, np.sqrt(var), 1.0)  # constant features: shift only

    def shift_scale(self) -> tuple[np.ndarray, np.ndarray]:
        """The float32 ``(shift, scale)`` ``(dim,)`` that :meth:`apply` uses: ``(x - shift) * scale``."""
        key = (self.count, self.mean.tobytes(), self.m2.tobytes())
        if getattr(self, "_key", None) != key:
            self._key = key
            self._shift = self.mean.astype(np.float32)  # (dim,)
            self._scale = (1.0 / self.std()).astype(np.float32)  # (dim,)
        return self._shift, self._scale

    def apply(self, x: np.ndarray, clip: float) -> np.ndarray:
        """Standardize and clip ``(..., dim)`` in float32 (4-5x faster than float64 on label batches)."""
        shift, scale = self.shift_scale()
        out = np.subtract(x, shift, dtype=np.float32)
        out *= scale
        return np.clip(out, -clip, clip, out=out)


class InverseDynamics:
    """``M_phi``: aggregate rollouts with :meth:`add`, fit with :meth:`train`, query with :meth:`label`."""

    def __init__(self, obs_dim: int, pos_dim: int, act_dim: int, config: InverseDynamicsConfig | None = None):
        if pos_dim <= 0:
            raise ValueError("inverse dynamics needs waypoint-space positions (info 'position', 'waypoint')")
        self.config = config or InverseDynamicsConfig()
        self.obs_dim, self.pos_dim, self.act_dim = obs_dim, pos_dim, act_dim
        # step_change (world and both frames, whose query starts with the world displacement): d more inputs,
        # the displacement's change from the last step's pace (mphi_inputs.change_block)
        self.step_change = bool(self.config.step_change) and self.config.frame in ("world", "both")
        self.query_dim = frame_dim(self.config.frame, pos_dim) + pos_dim * self.step_change  # (both: 2d [+ d])
        self.in_dim = obs_dim + self.query_dim
        self._rng = np.random.default_rng(int(self.config.seed))  # init, then minibatch draws
        self.net = LeanMLP((self.in_dim, *self.config.hidden, act_dim), self._rng)
        self.opt = FlatAdam(self.net.num_params, lr=self.config.lr)
        self.norm = RunningNorm(self.in_dim)
        self.iterations = 0  # training iterations done so far (x axis of the paper's Fig. 5)
        self._x = np.zeros((0, self.in_dim), np.float32)  # (N, obs + d) raw inputs, oldest first
        self._y = np.zeros((0, act_dim), np.float32)  # (N, act) target actions
        self._bx = self._by = None  # backing buffers of _x, _y once rows are added (_append)
        self._start = 0  # where _x starts in them
        self._lock = threading.Lock()

    @property
    def displacement_dim(self) -> int:
        """The displacement's columns among the inputs after the state (the change block, if any, follows)."""
        return self.query_dim - self.pos_dim * self.step_change

    @property
    def dataset_size(self) -> int:
        return int(self._x.shape[0])

    # -- data ----------------------------------------------------------------------------------------
    def add(self, transitions_list: Sequence[Transitions]) -> dict[str, float]:
        """Aggregate the training pairs (:func:`target_pairs`) of episodes passing the return filter
        (:func:`kept_episodes`); returns stats."""
        xs, ys, episodes, kept = [], [], 0, 0
        for tr in transitions_list:
            if len(tr) == 0:
                continue
            self._check(tr)
            eps, good = kept_episodes(tr, self.config.min_return, self.config.filter)  # paper: R < 5 out
            episodes, kept = episodes + eps.size, kept + good.size
            if good.size == 0:
                continue
            c = self.config
            s, disp, a = target_pairs(tr, c.frame, c.targets, c.horizon, self._rng, self.step_change)
            keep = np.isin(tr.episode[episode_end(tr) > np.arange(len(tr))], good)  # (T',) kept episodes
            if keep.all():  # the usual case once episodes pass: no copies
                xs.append(np.concatenate([s, disp], axis=1))
                ys.append(a)
                continue
            xs.append(np.concatenate([s[keep], disp[keep]], axis=1))  # (T', obs + d)
            ys.append(a[keep])  # (T', act)
        x = np.concatenate(xs).astype(np.float32) if xs else self._x[:0]
        y = np.concatenate(ys).astype(np.float32) if ys else self._y[:0]
        with self._lock:
            self.norm.update(x)
            self._append(x, y)
            size = self.dataset_size
        return {"episodes": float(episodes), "kept_episodes": float(kept),
                "kept_fraction": kept / episodes if episodes else 0.0,
                "added": float(x.shape[0]), "dataset_size": float(size)}

    def _append(self, x: np.ndarray, y: np.ndarray) -> None:
        """Rows onto the data set, the oldest dropped beyond ``max_dataset`` (FIFO); under the lock.

        The data set is a view of backing buffers twice its cap: new rows go after it, and only when
        there is no room left do the kept rows move to the front (a copy of the whole set every few
        generations instead of every generation)."""
        cap = self.config.max_dataset
        x, y = x[-cap:], y[-cap:]
        n, k = self.dataset_size, x.shape[0]
        keep = min(n, cap - k)
        end = self._start + n  # the row after the data in the buffers
        if self._bx is None or end + k > self._bx.shape[0]:  # no room: kept rows to the front
            bx = np.empty((2 * cap, self.in_dim), np.float32) if self._bx is None else self._bx  # (2 cap, in)
            by = np.empty((2 * cap, self.act_dim), np.float32) if self._by is None else self._by  # (2 cap, act)
            bx[:keep], by[:keep] = self._x[n - keep :], self._y[n - keep :]  # no overlap: keep <= cap < end - keep
            self._bx, self._by, start = bx, by, 0
        else:
            start = end - keep
        self._bx[start + keep : start + keep + k] = x
        self._by[start + keep : start + keep + k] = y
        self._start = start
        self._x, self._y = self._bx[start : start + keep + k], self._by[start : start + keep + k]

    def _check(self, tr: Transitions) -> None:
        got = (tr.state.shape[1], tr.position.shape[1], tr.action.shape[1])
        if got != (self.obs_dim, self.pos_dim, self.act_dim):
            raise ValueError(f"transitions have (obs, pos, act) dims {got}, model expects "
                             f"{(self.obs_dim, self.pos_dim, self.act_dim)}")

    # -- training ------------------------------------------------------------------------------------
    def train(self, num_steps: int | None = None) -> list[float]:
        """``num_steps`` Adam steps (default ``steps_per_generation``) on minibatches of the aggregated
        data set, drawn uniformly with replacement; returns the train loss (MSE) of every step. No data
        yet: no steps, ``[]``."""
        steps = self.config.steps_per_generation if num_steps is None else int(num_steps)
        B = self.config.batch_size
        if kernels.ENABLED and steps > 0:
            return self._train_compiled(steps, B)
        with self._lock:
            if self.dataset_size == 0 or steps <= 0:
                return []
            idx = self._rng.integers(0, self.dataset_size, size=(steps, B))  # (steps, B)
            x = self.norm.apply(self._x[idx.reshape(-1)], self.config.clip_input)  # (steps*B, in)
            x = x.reshape(steps, B, self.in_dim)  # (steps*B, in) -> (steps, B, in)
            y = self._y[idx]  # (steps, B, act)
        losses = []
        for k in range(steps):
            with self._lock:
                losses.append(self.net.mse_backward(x[k], y[k]))
                self.opt.step(self.net.flat, self.net.grad)
                self.iterations += 1
        return losses

    def _train_compiled(self, steps: int, B: int) -> list[float]:
        """:meth:`train`'s steps in one compiled call (``kernels.fit_mphi``): the same minibatch rows
        (the same draws from the same generator), the same Adam; equal to the NumPy loop to float
        tolerance. Holds the lock throughout, but not the GIL."""
        with self._lock:
            if self.dataset_size == 0:
                return []
            idx = self._rng.integers(0, self.dataset_size, size=(steps, B))  # (steps, B)
            shift, scale = self.norm.shift_scale()
            losses = np.zeros(steps)  # (steps,)
            opt = self.opt
            kernels.fit_mphi(self.net.flat, opt.m, opt.v, opt.t, np.array(self.net.sizes, np.int64),
                             self._x, self._y, idx, shift, scale, float(self.config.clip_input), float(opt.lr),
                             float(opt.b1), float(opt.b2), float(opt.eps), losses)
            opt.t += steps
            self.iterations += steps
        return losses.tolist()

    # -- queries -------------------------------------------------------------------------------------
    def label(self, states: np.ndarray, displacement: np.ndarray) -> np.ndarray:
        """``a_hat = M_phi(s, displacement)``: ``(..., obs)``, ``(..., d)`` -> ``(..., act)`` float32."""
        s = np.asarray(states, dtype=np.float32)
        d = np.asarray(displacement, dtype=np.float32)
        lead = s.shape[:-1]
        if kernels.ENABLED:  # one compiled pass, no concatenated copy of the inputs
            s2 = np.ascontiguousarray(s.reshape(-1, self.obs_dim))  # (N, obs)
            d2 = np.ascontiguousarray(d.reshape(-1, self.query_dim))  # (N, d)
            a = np.empty((s2.shape[0], self.act_dim), np.float32)  # (N, act)
            with self._lock:
                shift, scale = self.norm.shift_scale()
                kernels.label_mphi(self.net.flat, np.array(self.net.sizes, np.int64), s2, d2, shift, scale,
                                   float(self.config.clip_input), a)
            return a.reshape(*lead, self.act_dim)
        x = np.concatenate([s.reshape(-1, self.obs_dim), d.reshape(-1, self.query_dim)], axis=1)  # (N, in)
        a = np.empty((x.shape[0], self.act_dim), np.float32)  # (N, act)
        with self._lock:
            for i in range(0, x.shape[0], LABEL_CHUNK):  # cache-sized chunks (82k rows: 7.9 vs 8.7 ms)
                a[i : i + LABEL_CHUNK] = self.net.forward(self.norm.apply(x[i : i + LABEL_CHUNK],
                                                                          self.config.clip_input))
        return a.reshape(*lead, self.act_dim)

    def ask(self, states: np.ndarray, inputs: np.ndarray, max_displacement: float | None = None) -> np.ndarray:
        """Labels for a label source's kept inputs (``mphi_inputs.query_inputs``): the query clipped to
        ``max_displacement`` and, with ``step_change``, its change from the last step (kept after the query)
        appended: ``(..., obs)``, ``(..., d' [+ d])`` -> ``(..., act)``."""
        if not self.step_change:
            return self.label(states, clip_norm(inputs, max_displacement))
        inputs = np.asarray(inputs)
        dq = self.displacement_dim  # the query's width; the last step follows it
        h = self.config.horizon if self.config.targets == "chunk" else 1  # steps a query spans
        q = clip_norm(inputs[..., :dq], max_displacement)
        return self.label(states, query_change(q, inputs[..., dq:], self.pos_dim, h))

    def label_transitions(self, tr: Transitions) -> np.ndarray:
        """Labels ``(T, act)`` for every step of ``tr``: ``M_phi(s_t, waypoint_t - position_t)``."""
        c = self.config
        return self.ask(tr.state, query_inputs(tr, c.frame, c.query_scale, c.query_mix, self.step_change))

    def test_loss(self, states: np.ndarray, displacement: np.ndarray, reference_actions: np.ndarray) -> float:
        """Mean Euclidean distance between labels and reference actions (paper, Fig. 5 test loss)."""
        a = self.label(states, displacement).reshape(-1, self.act_dim)  # (N, act)
        ref = np.asarray(reference_actions, dtype=np.float32).reshape(-1, self.act_dim)
        return float(np.linalg.norm(a - ref, axis=1).mean()) if a.shape[0] else float("nan")

    # -- state ---------------------------------------------------------------------------------------
    def newest(self, rows: int) -> tuple[np.ndarray, np.ndarray]:
        """Copies of the newest ``rows`` rows of the data set: inputs ``(r, obs + d)``, targets ``(r, act)``."""
        with self._lock:
            r = min(int(rows), self.dataset_size)
            return self._x[self.dataset_size - r :].copy(), self._y[self.dataset_size - r :].copy()

    def set_data(self, x: np.ndarray, y: np.ndarray) -> None:
        """Replace the aggregated data set (a resume rebuilding it from saved parts; normalizer unchanged)."""
        x, y = np.asarray(x, np.float32), np.asarray(y, np.float32)
        if x.ndim != 2 or x.shape[1] != self.in_dim or y.shape != (x.shape[0], self.act_dim):
            raise ValueError(f"data set of shapes {x.shape}, {y.shape} does not fit inputs {self.in_dim}, "
                             f"actions {self.act_dim}")
        with self._lock:
            self._x, self._y = x[-self.config.max_dataset :], y[-self.config.max_dataset :]
            self._bx = self._by = None

    def state_dict(self, with_training: bool = True, with_data: bool = True) -> dict[str, np.ndarray]:
        """Arrays only (safetensors-ready). ``with_training=False``: just what :meth:`label` needs
        (network + normalizer); ``True`` adds optimizer, RNG and (``with_data``) the aggregated data set
        (exact resume; without it, the caller restores the data with :meth:`set_data`)."""
        with self._lock:
            out = {"meta/dims": np.array([self.obs_dim, self.pos_dim, self.act_dim], np.int64),
                   "meta/hidden": np.array(self.config.hidden, np.int64),
                   "norm/count": np.array([self.norm.count]), "norm/mean": self.norm.mean.copy(),
                   "norm/m2": self.norm.m2.copy(), "net/flat": self.net.flat.copy()}
            if with_training:
                out["meta/iterations"] = np.array([self.iterations], np.int64)
                out["rng/state"] = _rng_words(self._rng)
                out["data/size"] = np.array([self.dataset_size], np.int64)
                if with_data:
                    out["data/x"], out["data/y"] = self._x.copy(), self._y.copy()
                out["optim/m"], out["optim/v"] = self.opt.m.copy(), self.opt.v.copy()
                out["optim/t"] = np.array([self.opt.t], np.int64)
        return out

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        dims = tuple(int(v) for v in state["meta/dims"])
        hidden = tuple(int(v) for v in state["meta/hidden"])
        if dims != (self.obs_dim, self.pos_dim, self.act_dim) or hidden != tuple(self.config.hidden):
            mine = (self.obs_dim, self.pos_dim, self.act_dim)
            raise ValueError(f"state is for dims {dims} hidden {hidden}, model has {mine} "
                             f"hidden {tuple(self.config.hidden)}")
        flat = np.asarray(state["net/flat"], np.float32).reshape(-1)
        if flat.shape[0] != self.net.num_params:
            raise ValueError(f"state has {flat.shape[0]} network parameters, model has {self.net.num_params}")
        with self._lock:
            self.net.flat[...] = flat
            self.norm.count = float(state["norm/count"][0])
            self.norm.mean, self.norm.m2 = np.array(state["norm/mean"]), np.array(state["norm/m2"])
            if "rng/state" in state:
                self.iterations = int(state["meta/iterations"][0])
                self._rng = _rng_from_words(np.asarray(state["rng/state"]))
                if "data/x" in state:
                    self._x = np.array(state["data/x"], np.float32)
                    self._y = np.array(state["data/y"], np.float32)
                    self._bx = self._by = None
                self.opt.m[...] = np.asarray(state["optim/m"], np.float32).reshape(-1)
                self.opt.v[...] = np.asarray(state["optim/v"], np.float32).reshape(-1)
                self.opt.t = int(state["optim/t"][0])

    @classmethod
    def from_state_dict(cls, state: dict[str, np.ndarray], config: InverseDynamicsConfig | None = None):
        """Rebuild a model (e.g. on a worker, for labelling) from :meth:`state_dict` arrays."""
        obs, pos, act = (int(v) for v in state["meta/dims"])
        cfg = replace(config or InverseDynamicsConfig(), hidden=tuple(int(v) for v in state["meta/hidden"]))
        model = cls(obs, pos, act, cfg)
        model.load_state_dict(state)
        return model



def _rng_words(rng: np.random.Generator) -> np.ndarray:
    """A PCG64 generator's full state as 6 uint64 words (state hi/lo, increment hi/lo, buffered uint32
    flag and value), for npz."""
    full = rng.bit_generator.state
    st, mask = full["state"], (1 << 64) - 1
    return np.array([st["state"] >> 64, st["state"] & mask, st["inc"] >> 64, st["inc"] & mask,
                     full["has_uint32"], full["uinteger"]], np.uint64)


def _rng_from_words(words: np.ndarray) -> np.random.Generator:
    w = [int(x) for x in words.astype(np.uint64)]
    if len(w) != 6:
        raise ValueError(f"rng state needs 6 words, got {len(w)}")
    bg = np.random.PCG64()
    bg.state = {"bit_generator": "PCG64", "state": {"state": (w[0] << 64) | w[1], "inc": (w[2] << 64) | w[3]},
                "has_uint32": w[4], "uinteger": w[5]}
    return np.random.Generator(bg)
