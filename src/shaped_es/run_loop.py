"""The one run loop every method shares (the SB3 ``BaseAlgorithm`` habit: one loop, each method its step).

:class:`RunLoop` owns what the ES trainer (``trainer.Trainer``) and PPO (``baselines.ppo.PPORun``) do
alike: hold the run directory's lock, restore the newest checkpoint (check it belongs to this run, read
the counters, ``RunStore.prepare_recovery``), and once its first generation ran repair the directory
(``latest.json``, rows past the checkpoint) and write the config it runs with (a resume's new
``--generations`` / ``--executor`` / ``--workers``): a resume that fails before changes nothing; then generation after generation append the metrics rows a step completes (``metrics.csv``,
TensorBoard, the progress bar) and checkpoint every ``checkpoint_every`` generations and at the last
one. A method supplies:

- ``step(g)``: run generation ``g``, return the metrics rows completed meanwhile (in generation order);
- ``finish()``: the rows still pending after the last generation's step (default none);
- ``checkpoint_state()``: the arrays and the method's own meta of a checkpoint (``self.c`` is added);
- ``load_state(arrays, meta)``: load them, raising ``KeyError``/``ValueError``/... if they do not fit
  (nothing on disk changes before it returns); ``resumed(arrays, meta)``: what follows once the
  counters are back (default nothing);
- ``close()``: release what it holds, calling ``super().close()``;
- ``columns()``: the ``metrics.csv`` columns its rows fill (default :data:`BASE_COLUMNS`; a guide adds
  the ones it fills with its config, ``guides.NoGuide.metric_keys``), so no column stays always empty;
- ``best_generation``: set to the generations done when its best policy was found (checkpointed).

After each row the loop calls the run's callbacks (``callback``: a function ``row -> bool | None`` or a
:class:`shaped_es.monitor.callbacks.Callback`, or a list of them; ``False`` stops the run, as SB3's
``BaseCallback._on_step``), and ``stop_at`` (``--stop-at R``) ends the run once a test reward reaches
``R``. A stopped run completes the rows still waiting for their test episodes and checkpoints; one
stopped by ``stop_at`` counts as finished (:func:`run_finished`) while its best test reward reaches its
config's ``stop_at`` (``resume --no-stop-at`` or a higher ``--stop-at`` continues it).
"""

from __future__ import annotations

import contextlib
import math
import sys
import time

from shaped_es.config import RunConfig
from shaped_es.monitor.callbacks import as_callbacks
from shaped_es.monitor.progress import ProgressDisplay
from shaped_es.rundir import metrics_csv
from shaped_es.rundir.atomic import atomic_write_text
from shaped_es.rundir.meta import Counters, checkpoint_mismatch, config_digest
from shaped_es.rundir.prune import refuse_pruned
from shaped_es.rundir.recovery import rows_covered
from shaped_es.rundir.store import RunStore, StoreError

# the columns every method's metrics row holds, in metrics.csv's order
BASE_COLUMNS = ("generation", "env_steps", "wall_time_s", "cpu_time_s", "train_reward_mean", "train_reward_max",
                "train_reward_min", "test_reward_mean", "test_reward_std", "test_reward_best_so_far",
                "test_env_steps", "gen_env_steps", "gen_time_s", "rollout_time_s", "update_norm")
STOP_AT = "stop_at"  # a checkpoint's ``stopped``: the run reached ``cfg.stop_at`` (finished)
CALLBACK = "callback"  # ... a callback stopped it (resumable)


class RunLoop:
    label = "train"  # the progress bar's label

    def __init__(self, cfg: RunConfig, store: RunStore, method: str, progress: bool = True, callback=None):
        self.cfg, self.store, self.method, self.progress = cfg, store, method, progress
        # the run's start-up (worker pools, the env probe, the shaped method's label probe) begins here:
        # the progress line's elapsed time counts it (wall_time_s counts the label probe)
        self._started = time.perf_counter()
        self.c = Counters()
        # generations done when the best policy was found (0: the initial one; None: an old checkpoint's)
        self.best_generation: int | None = 0
        self.stopped: str | None = None  # STOP_AT or CALLBACK once the run ended early
        self.callbacks = as_callbacks(callback)
        self._restored_stop: str | None = None
        self._rows_kept = 0  # metrics rows a restored checkpoint covers (the resume writes the rest again)
        self._repair = lambda: None  # restore's repair of the run directory, once a first generation ran
        self._crossed: tuple[int, float] | None = None  # (generation, test reward) that reached stop_at
        self._tb = None
        self._wandb = None

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

    def columns(self) -> tuple[str, ...]:
        return BASE_COLUMNS

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
        if self._restored_stop == STOP_AT and reached_stop_at(self.cfg, self.c.best_test_reward):  # finished
            self._repair()
            self.close()
            return rows
        for cb in self.callbacks:
            cb.on_start(self)
        # elapsed: a resumed run's saved wall time, plus this process's start-up
        bar = ProgressDisplay(self.cfg.generations, self.c.generation, enabled=self.progress, label=self.label,
                              elapsed=self.c.wall_time_s + time.perf_counter() - self._started)
        if self.c.generation and self.progress:  # a resumed run's counters continue (labels accepted/judged):
            # the rows the checkpoint covers, one per generation; not those it writes again (rows that waited
            # for their test episodes, which a killed run may have written after its checkpoint) nor repeats
            bar.count_labels(metrics_csv.rows_up_to(self.store.metrics_path, self._rows_kept - 1)[1])
        saved = False
        try:
            for g in range(self.c.generation, self.cfg.generations):
                done = self.step(g)
                if not saved:  # the restore held up through a first generation: resume's changes stay
                    self._repair()  # latest.json and the rows past the checkpoint (RunStore.prepare_recovery)
                    self.store.save_config(self.cfg)
                    saved = True
                last = g + 1 == self.cfg.generations
                if last:
                    done += self.finish()
                stop = self._write_rows(done, rows, bar)
                if stop and not last:  # the rows still waiting for their test episodes, then stop
                    self._write_rows(self.finish(), rows, bar)
                    self.stopped = stop
                video = self.cfg.video_every is not None and (g + 1) % self.cfg.video_every == 0
                if (g + 1) % self.cfg.checkpoint_every == 0 or last or self.stopped or video:
                    self.checkpoint()
                if video:  # trained.video.VideoCallback renders from the checkpoint just written
                    for cb in self.callbacks:
                        cb.on_checkpoint(g + 1)
                if self.stopped:
                    self._say_stopped(rows)
                    break
            if not saved:  # nothing left to run (a finished run resumed)
                self._repair()
                self.store.save_config(self.cfg)
        finally:
            bar.close()
            self.close()
        for cb in self.callbacks:
            cb.on_end(rows)
        return rows

    def _write_rows(self, done: list[dict], rows: list[dict], bar: ProgressDisplay) -> str | None:
        """Write each row (metrics.csv, TensorBoard, W&B, the progress bar), then call the callbacks;
        returns why the run should stop (``STOP_AT`` / ``CALLBACK``), or None."""
        stop = None
        for raw in done:
            row = self.metrics_row(raw)
            self.store.append_metrics(row)
            self._log_tb(row)
            self._log_wandb(row)
            rows.append(row)
            bar.update(int(row["generation"]), row)
            test = row.get("test_reward_mean")
            if self.cfg.stop_at is not None and test is not None and test >= self.cfg.stop_at:
                if self._crossed is None:  # the row that crossed, not a later one's (test rows may lag)
                    self._crossed = (int(row["generation"]), float(test))
                stop = stop or STOP_AT
            if any([cb.on_generation(row) is False for cb in self.callbacks]):  # every callback sees it
                stop = stop or CALLBACK
        return stop

    def metrics_row(self, row: dict) -> dict:
        """``row`` as ``metrics.csv`` holds it: every declared column (:meth:`columns`), in order; a value
        in an undeclared column is a bug of the method (a column it fills but does not declare)."""
        cols = self.columns()
        stray = sorted(k for k, v in row.items() if k not in cols and v is not None)
        if stray:
            raise RuntimeError(f"{self.method}: metrics columns {stray} are filled but not declared "
                               f"(columns() / the guide's metric_keys())")
        return {k: row.get(k) for k in cols}

    def _say_stopped(self, rows: list[dict]) -> None:
        if self.stopped == STOP_AT:
            gen, test = self._crossed
            why = f"gen {gen + 1}'s test reward of {test:.2f} reached --stop-at {self.cfg.stop_at:g}"
        else:
            why = "a callback returned False"
        if self.progress:
            print(f"[{self.label}] stopped after {self.c.generation} of {self.cfg.generations} generations: "
                  f"{why}", file=sys.stderr, flush=True)

    # -- checkpoint and resume ---------------------------------------------------------------------
    def checkpoint(self) -> None:
        """Save the method's state with the counters, the config digest and the method's name."""
        arrays, extra = self.checkpoint_state()
        meta = {**self.c.__dict__, "config_digest": config_digest(self.cfg), "method": self.method,
                "best_generation": self.best_generation, "stopped": self.stopped, **extra}
        if not math.isfinite(meta["best_test_reward"]):
            meta["best_test_reward"] = None
        self.store.save_checkpoint(self.c.generation, arrays, meta, keep=self.cfg.keep_checkpoints)

    def restore(self) -> bool:
        """Load the newest complete checkpoint if any (whatever ``latest.json`` says), after checking it
        belongs to this run; then ``RunStore.prepare_recovery`` deletes what a killed run left, and its
        repair (once the first generation ran: a resume that fails before changes nothing) drops the
        metrics rows past the checkpoint. Returns True if one was loaded. Nothing on disk changes when
        the checkpoint does not fit."""
        refuse_pruned(self.store)  # its data parts and shards are gone: no exact resume (one line)
        self.store.check_writable_layout(self.columns(), self.cfg.tensorboard)
        loaded = self.store.load_checkpoint()
        if loaded is None:
            self._repair = self.store.prepare_recovery(loaded=None, uncheckpointed=self.cfg.checkpoint_every)[1]
            return False
        arrays, meta = loaded
        where = f"checkpoint gen_{meta['generation']:06d} in {self.store.ckpt_dir}"
        if (why := checkpoint_mismatch(meta, self.cfg, self.method, self.store.config_path)) is not None:
            raise StoreError(f"{where} was made with a different config{why}")
        try:
            counters = read_counters(meta)
            self.load_state(arrays, meta)
        except (KeyError, ValueError, TypeError, IndexError, RuntimeError) as exc:
            msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            msg = f"it lacks {msg}" if isinstance(exc, KeyError) else msg
            raise StoreError(f"{where} does not fit this run: {msg}{self.store.fallback_hint(meta['generation'])}"
                             ) from None
        self._repair = self.store.prepare_recovery(loaded=loaded)[1]
        self._rows_kept = rows_covered(loaded)  # the rows the resume keeps; it writes the rest again
        for k, v in counters.items():
            setattr(self.c, k, v)
        best = meta.get("best_generation")
        self.best_generation = best if type(best) is int else None
        self._restored_stop = meta.get("stopped")
        self.resumed(arrays, meta)
        return True

    # -- output --------------------------------------------------------------------------------------
    def _log_tb(self, row: dict) -> None:
        """The row as TensorBoard scalars ``train/``, ``test/``, ``shaping/``, ``time/``, ``misc/`` at
        step ``row["env_steps"]`` (:mod:`shaped_es.monitor.tensorboard`)."""
        if not self.cfg.tensorboard:
            return
        from shaped_es.monitor import tensorboard as tblog

        if self._tb is None:
            self._tb = tblog.open_writer(self.store.root / "tb", row)
        tblog.log_row(self._tb, row)

    def _log_wandb(self, row: dict) -> None:
        """The row in Weights & Biases under the same ``GROUP/column`` names (:mod:`shaped_es.monitor.wandb_log`)."""
        if not self.cfg.wandb.enabled:
            return
        from shaped_es.monitor import wandb_log

        if self._wandb is None:
            self._wandb = wandb_log.open_run(self.store.root, self.cfg.wandb, self.cfg.model_dump(mode="json"),
                                             atomic_write_text)
            if self.progress:
                print(f"[{self.label}] W&B: {wandb_log.where(self._wandb)}", file=sys.stderr, flush=True)
        wandb_log.log_row(self._wandb, row)

    def close(self) -> None:
        if self._tb is not None:
            self._tb.close()
            self._tb = None
        if self._wandb is not None:
            self._wandb.finish()
            self._wandb = None


def run_finished(cfg: RunConfig, store: RunStore) -> bool:
    """The run's newest checkpoint covers ``cfg.generations``, or the run stopped at ``cfg.stop_at``."""
    meta = store.checkpoint_meta()
    if meta is None:
        return False
    return int(meta["generation"]) >= cfg.generations or stopped_at(cfg, meta)


def reached_stop_at(cfg: RunConfig, best: float | None) -> bool:
    """A best test reward of ``best`` reaches ``cfg.stop_at`` (a stop_at of None is never reached)."""
    return cfg.stop_at is not None and best is not None and best >= cfg.stop_at


def stopped_at(cfg: RunConfig, meta: dict) -> bool:
    """The checkpoint ``meta`` ended its run at ``stop_at`` and that still holds under ``cfg``: a resume
    with ``stop_at`` None (``--no-stop-at``) or above the best test reward continues the run."""
    return meta.get("stopped") == STOP_AT and reached_stop_at(cfg, meta.get("best_test_reward"))


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
        if isinstance(v, int) and not isinstance(v, bool) and not -2**63 <= v < 2**63:  # math.isfinite overflows
            raise ValueError(f"malformed counter '{k}': {str(v)[:20]}... is out of range")
        if isinstance(v, bool) or not isinstance(v, int if count else (int, float)) or \
                not math.isfinite(v) or (count and v < 0):
            raise ValueError(f"malformed counter '{k}': {v!r}")
        out[k] = int(v) if count else float(v)
    if out["generation"] != meta["generation"]:
        raise ValueError("counter generation differs from the checkpoint's")
    return out
