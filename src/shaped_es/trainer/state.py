"""What an ES run's checkpoint holds and how a resume takes it back: the strategy's and the guide's state,
the best and mean policies, the ``es.obs_norm`` statistics, and the rows still waiting for their test
episodes (resume submits them again); a state holding inf/NaN is never saved (:class:`DivergedError`).

:class:`CheckpointState` is :class:`~shaped_es.trainer.Trainer`'s part that does this.
"""

from __future__ import annotations

import numpy as np

from shaped_es.methods import METHODS
from shaped_es.policies import ObsNorm, ObsStats
from shaped_es.trainer.rows import _Row


class DivergedError(RuntimeError):
    """The search went non-finite (inf/NaN mean or state); the run stops, its last good checkpoint kept."""


class CheckpointState:
    """The checkpoint hooks of :class:`~shaped_es.trainer.Trainer` (``RunLoop.checkpoint_state``,
    ``load_state``, ``resumed``)."""

    def checkpoint_state(self) -> tuple[dict, dict]:
        arrays = {f"strategy/{k}": v for k, v in self.strategy.state_dict().items()}
        arrays |= {f"guide/{k}": v for k, v in self.guide.state_dict().items()}
        arrays["policy/best"] = self.best_params
        arrays["policy/mean"] = np.asarray(self.strategy.mean, dtype=np.float32)
        if self.obs_stats is not None:  # float64: a resume continues with exactly these statistics
            arrays["policy/obs_count"] = np.array(self.obs_stats.count, dtype=np.float64)
            arrays["policy/obs_mean"], arrays["policy/obs_m2"] = self.obs_stats.mean, self.obs_stats.m2
            arrays["policy/best_obs_mean"], arrays["policy/best_obs_std"] = self.best_norm.mean, self.best_norm.std
        meta = {"policy": {"obs_dim": self.spec.obs_dim, "act_dim": self.spec.act_dim,
                           "hidden": list(self.spec.hidden)}}
        # Rows whose test episodes are still running: resume submits them again (same seeds).
        meta["waiting_rows"] = [_jsonable(item.row) for item in self._waiting]
        for i, item in enumerate(self._waiting):
            if item.theta is not None:
                arrays[f"waiting/{i}"] = item.theta
            if item.obs_norm is not None:
                arrays[f"waiting/{i}/obs_mean"], arrays[f"waiting/{i}/obs_std"] = item.obs_norm.mean, item.obs_norm.std
        bad = _non_finite(arrays)
        if bad:  # never save a state a resume could not continue from; the previous one stays
            raise DivergedError(self._diverged(self.c.generation - 1, f"the state to checkpoint ({bad[0]})"))
        return arrays, meta

    def _diverged(self, g: int, what: str) -> str:
        """The error line of generation ``g`` (0-based), named from 1 as the progress line and the checkpoint
        names count (checkpoint N: after generation N)."""
        gens = self.store.checkpoints()
        kept = f"generation {gens[-1]}" if gens else "none yet"
        knobs = " / ".join(METHODS[self.cfg.method].knobs)
        return (f"generation {g + 1}: {what} became non-finite (inf/NaN); the run stopped, its last good "
                f"checkpoint ({kept}) is kept; lower {knobs}")

    def load_state(self, arrays: dict, meta: dict) -> None:
        bad = _non_finite(arrays)
        if bad:  # what checkpoint_state never saves: the run would blame its env for the NaN actions
            raise ValueError(f"{bad[0]} holds non-finite values (inf/NaN)")
        waiting = meta.get("waiting_rows", [])
        if not isinstance(waiting, list) or not all(
                isinstance(r, dict) and type(r.get("generation")) is int for r in waiting):
            raise ValueError("malformed waiting_rows")
        self.strategy.load_state_dict(_sub(arrays, "strategy/"))
        self.guide.load_state_dict(_sub(arrays, "guide/"))
        self.best_params = arrays["policy/best"]
        if np.shape(self.best_params) != (self.spec.num_params,):
            raise ValueError(f"policy/best has shape {np.shape(self.best_params)}")
        if self.obs_stats is not None:
            d = self.spec.obs_dim
            self.obs_stats = ObsStats(float(_shaped(arrays, "policy/obs_count", ())),
                                      _shaped(arrays, "policy/obs_mean", (d,)).astype(np.float64),
                                      _shaped(arrays, "policy/obs_m2", (d,)).astype(np.float64))
            self.best_norm = ObsNorm(_shaped(arrays, "policy/best_obs_mean", (d,)).astype(np.float32),
                                     _shaped(arrays, "policy/best_obs_std", (d,)).astype(np.float32))

    def resumed(self, arrays: dict, meta: dict) -> None:
        """Submit the test episodes of the rows still waiting at the checkpoint again (``recover`` kept
        the metrics rows before the first of them)."""
        self._waiting = []
        for i, row in enumerate(meta.get("waiting_rows", [])):
            item = _Row(dict(row))
            if f"waiting/{i}" in arrays:
                norm = None
                if f"waiting/{i}/obs_mean" in arrays:
                    norm = ObsNorm(np.asarray(arrays[f"waiting/{i}/obs_mean"], np.float32),
                                   np.asarray(arrays[f"waiting/{i}/obs_std"], np.float32))
                self._submit_eval(item, np.asarray(arrays[f"waiting/{i}"], dtype=np.float32),
                                  int(row["generation"]), norm)
            self._waiting.append(item)


def _jsonable(row: dict) -> dict:
    """A metrics row with plain Python numbers (numpy scalars are not JSON)."""
    return {k: (v.item() if isinstance(v, np.generic) else v) for k, v in row.items()}


def _non_finite(arrays: dict[str, np.ndarray]) -> list[str]:
    """The float arrays holding inf/NaN, the search's, the policies' and the guide's (M_phi, its
    normaliser, the learner): a checkpoint holds none."""
    return [k for k, v in arrays.items() if np.asarray(v).dtype.kind in "fc" and not np.isfinite(v).all()]


def _shaped(arrays: dict[str, np.ndarray], key: str, shape: tuple) -> np.ndarray:
    """``arrays[key]`` checked to have ``shape`` (``KeyError`` if missing, ``ValueError`` if not)."""
    v = np.asarray(arrays[key])
    if v.shape != shape:
        raise ValueError(f"{key} has shape {v.shape}, expected {shape}")
    return v


def _sub(arrays: dict[str, np.ndarray], prefix: str) -> dict[str, np.ndarray]:
    return {k[len(prefix):]: v for k, v in arrays.items() if k.startswith(prefix)}
