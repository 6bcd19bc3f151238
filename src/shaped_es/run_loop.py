"""The one run loop every method shares (the SB3 ``BaseAlgorithm`` habit: one loop, each method its step).

:class:`RunLoop` owns what the ES trainer (``trainer.Trainer``) and PPO (``baselines.ppo.PPORun``) do
alike: hold the run directory's lock, restore the newest checkpoint (check it belongs to this run, read
the counters, ``RunStore.recover``), write the config it runs with once its first generation ran (a
resume's new ``--generations`` / ``--executor`` / ``--workers``: a resume that fails changes no
config), then generation after generation append the metrics rows a step completes (``metrics.csv``,
TensorBoard, the progress bar) and checkpoint every ``checkpoint_every`` generations and at the last
one. A method supplies:

- ``step(g)``: run generation ``g``, return the metrics rows completed meanwhile (in generation order);
- ``finish()``: the rows still pending after the last generation's step (default none);
- ``checkpoint_state()``: the arrays and the method's own meta of a checkpoint (``self.c`` is added);
- ``load_state(arrays, meta)``: load them, raising ``KeyError``/``ValueError``/... if they do not fit
  (nothing on disk changes before it returns); ``resumed(arrays, meta)``: what follows once the
  counters are back (default nothing);
- ``close()``: release what it holds, calling ``super().close()``.
"""

from __future__ import annotations

import contextlib
import math

from shaped_es.config import RunConfig
from shaped_es.progress import ProgressDisplay
from shaped_es.run_meta import Counters, config_digest
from shaped_es.store import RunStore, StoreError


class RunLoop:
    label = "train"  # the progress bar's label

    def __init__(self, cfg: RunConfig, store: RunStore, method: str, progress: bool = True):
        self.cfg, self.store, self.method, self.progress = cfg, store, method, progress
        self.c = Counters()
        self._tb = None

    # -- supplied by each method -------------------------------------------------------------------
    def step(self, g: int) -> list[dict]:
        raise NotImplementedError

    def finish(self) -> list[dict]:
        return []

    def checkpoint_state(self) -> tuple[dict, dict]:
        raise NotImplementedError

    def load_state(self, arrays: dict, meta: dict) -> None:
        raise NotImplementedError

    def resumed(self, arrays: dict, meta: dict) -> None:
        pass

    # -- the loop ----------------------------------------------------------------------------------
    def run(self) -> list[dict]:
        """Run (or continue) to ``cfg.generations``; returns the rows written by this call."""
        with contextlib.ExitStack() as stack:
            try:  # one writer per run directory (StoreError naming the holder otherwise)
                stack.enter_context(self.store.lock())
            except BaseException:
                self.close()
                raise
            return self._loop()

    def _loop(self) -> list[dict]:
        self.restore()
        rows: list[dict] = []
        bar = ProgressDisplay(self.cfg.generations, self.c.generation, enabled=self.progress,
                              label=self.label)
        saved = False
        try:
            for g in range(self.c.generation, self.cfg.generations):
                done = self.step(g)
                if not saved:  # the restore held up through a first generation: resume's changes stay
                    self.store.save_config(self.cfg)
                    saved = True
                last = g + 1 == self.cfg.generations
                if last:
                    done += self.finish()
                for row in done:
                    self.store.append_metrics(row)
                    self._log_tb(row)
                    rows.append(row)
                    bar.update(int(row["generation"]), row)
                if (g + 1) % self.cfg.checkpoint_every == 0 or last:
                    self.checkpoint()
            if not saved:  # nothing left to run (a finished run resumed)
                self.store.save_config(self.cfg)
        finally:
            bar.close()
            self.close()
        return rows

    # -- checkpoint and resume ---------------------------------------------------------------------
    def checkpoint(self) -> None:
        """Save the method's state with the counters, the config digest and the method's name."""
        arrays, extra = self.checkpoint_state()
        meta = {**self.c.__dict__, "config_digest": config_digest(self.cfg), "method": self.method, **extra}
        if not math.isfinite(meta["best_test_reward"]):
            meta["best_test_reward"] = None
        self.store.save_checkpoint(self.c.generation, arrays, meta, keep=self.cfg.keep_checkpoints)

    def restore(self) -> bool:
        """Load the newest complete checkpoint if any (whatever ``latest.json`` says), after checking it
        belongs to this run; then ``RunStore.recover`` deletes what a killed run left and drops the
        metrics rows past the checkpoint. Returns True if one was loaded. Nothing on disk changes when
        the checkpoint does not fit."""
        loaded = self.store.load_checkpoint()
        if loaded is None:
            self.store.recover(loaded=None)
            return False
        arrays, meta = loaded
        where = f"checkpoint gen_{meta['generation']:06d} in {self.store.ckpt_dir}"
        if meta.get("method", self.method) != self.method or \
                meta.get("config_digest") != config_digest(self.cfg):
            raise StoreError(f"{where} was made with a different config")
        try:
            counters = read_counters(meta)
            self.load_state(arrays, meta)
        except (KeyError, ValueError, TypeError, IndexError, RuntimeError) as exc:
            msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            msg = f"it lacks {msg}" if isinstance(exc, KeyError) else msg
            raise StoreError(f"{where} does not fit this run: {msg}") from None
        self.store.recover(loaded=loaded)
        for k, v in counters.items():
            setattr(self.c, k, v)
        self.resumed(arrays, meta)
        return True

    # -- output --------------------------------------------------------------------------------------
    def _log_tb(self, row: dict) -> None:
        """The row as TensorBoard scalars ``train/``, ``test/``, ``shaping/``, ``time/``, ``misc/`` at
        step ``row["env_steps"]`` (:mod:`shaped_es.tblog`)."""
        if not self.cfg.tensorboard:
            return
        from shaped_es import tblog

        if self._tb is None:
            self._tb = tblog.open_writer(self.store.root / "tb", row)
        tblog.log_row(self._tb, row)

    def close(self) -> None:
        if self._tb is not None:
            self._tb.close()
            self._tb = None


def read_counters(meta: dict) -> dict:
    """The checkpoint's :class:`Counters` (``best_test_reward`` None: none yet), checked: counts are
    non-negative integers, times finite numbers, ``generation`` the checkpoint's own."""
    out = {}
    for k in Counters.__dataclass_fields__:
        v = meta[k]
        if k == "best_test_reward" and v is None:
            out[k] = -math.inf
            continue
        count = k in ("generation", "env_steps")
        if isinstance(v, bool) or not isinstance(v, int if count else (int, float)) or \
                not math.isfinite(v) or (count and v < 0):
            raise ValueError(f"malformed counter '{k}': {v!r}")
        out[k] = int(v) if count else float(v)
    if out["generation"] != meta["generation"]:
        raise ValueError("counter generation differs from the checkpoint's")
    return out
