"""What the shaped guide does beside the generation loop's critical path, and when its products are
durable: M_phi's new training pairs and gradient steps (then the mechanism's background job) in the
shaping thread, started by ``begin_generation`` while the workers roll out and joined in ``after_tell``;
the data parts' and shards' writes in the writer thread, joined before each checkpoint; and, once that
checkpoint is on disk, the pruning of the shards and data parts no kept checkpoint reads.

``BackgroundWork`` is a part of ``guides/shaped.py``'s ``ShapedGuide`` (its base class), which owns the
state these methods use: ``mphi``, ``track`` and ``rivals`` (the M_phi tracks, ``_tracks``), ``labels``,
``spec``, ``sh``, ``query_clip`` and ``step_norm``, ``_cache`` (generation -> block), ``_pending`` (this
generation's metrics), ``_thread`` and ``_thread_error``, ``_writer``, ``_writes`` and ``_write_time``,
``traj_root``, ``_saved`` and ``_ckpt_margin``.
"""

from __future__ import annotations

import time

import numpy as np

from shaped_es.data import Transitions, concat_members
from shaped_es.guides.rival import owned
from shaped_es.shaping.trajectories import delete_generations, list_generations

FIT_TEST_ROWS = 4096  # held-out fit measured on about this many rows


class BackgroundWork:
    """The shaping thread and the writer thread of a :class:`~shaped_es.guides.shaped.ShapedGuide` (the
    module docstring names the guide's attributes these methods use)."""

    # -- M_phi's data and training, in the shaping thread -------------------------------------------
    def _add_mphi_data(self, generation: int, data: list[Transitions]) -> bool:
        """M_phi's training pairs from generation ``generation - 1``'s recorded steps ``data`` (one
        Transitions); True: train it."""
        trained = self.mphi.iterations > 0
        stats, x, y, write = self.track.add(generation, data, self._writer)  # g-1's kept training pairs
        if x is not None:
            rows = x.shape[0]
            self._writes.append(write)
            if trained:  # M_phi's held-out fit on them, before it trains on them
                sub = slice(None, None, max(1, rows // FIT_TEST_ROWS))  # every k-th row: a fixed sample
                obs = self.spec.obs_dim
                self._pending["mphi_fit_test_loss"] = self.mphi.test_loss(x[sub, :obs], x[sub, obs:], y[sub])
            obs = self.spec.obs_dim  # (rows,) training displacement norms (not step_change's block after them)
            norms = np.linalg.norm(x[:, obs : obs + self.mphi.displacement_dim], axis=1)
            cnt = self.step_norm[0] + norms.size
            self.step_norm = np.array([cnt, self.step_norm[1] + (norms.sum() - norms.size *
                                                                  self.step_norm[1]) / cnt])
            self.labels.max_displacement = self.labels_max_displacement()
        self._pending.update(mphi_dataset_size=stats["dataset_size"],
                             mphi_kept_fraction=stats["kept_fraction"])
        return True

    def _background(self, generation: int, data: list[Transitions], train: bool, job) -> None:
        """The shaping thread: M_phi's new data and training steps, then the mechanism's job (which may
        label with it). An error is raised again where the thread is joined."""
        try:
            if train:
                blk = self._cache.get(generation - 1)
                if data:  # one Transitions for the generation: per-step work once, not per member
                    data = [blk.big if blk is not None else concat_members(data)[0]]
                self._add_mphi_data(generation, data)
                t0 = time.perf_counter()
                losses = self.mphi.train()
                self._pending["mphi_train_loss"] = float(np.mean(losses)) if losses else None
                self._pending["mphi_iterations"] = self.mphi.iterations
                for r in owned(self.rivals):  # the rival models on the same steps (each its own pairs)
                    write = r.track.add(generation, data, self._writer)[3]
                    self._writes.extend([write] if write is not None else [])
                    r.track.mphi.train()
                self._pending["time_mphi_s"] = time.perf_counter() - t0
            if job is not None:
                job()
        except BaseException as exc:  # noqa: BLE001 - handed to the joining thread
            self._thread_error = exc

    def _early_mphi(self, generation: int) -> None:
        """``shaping.early_mphi``: at generation 0's end, M_phi and the rival models take in its steps and train
        (what ``begin_generation`` would do beside generation 1's rollouts, and then skips), so generation 0's
        clone, judged beside generation 1, has labels."""
        if self.sh.early_mphi and generation == 0 and self.mphi is not None and self.awake:
            self._background(1, [t for t in self._generation(0) if len(t)], True, None)
            self._join_thread()

    def _join_thread(self) -> None:
        if self._thread is not None:
            self._thread.join()
            self._thread = None
        err, self._thread_error = self._thread_error, None
        if err is not None:
            raise err

    def labels_max_displacement(self) -> float | None:
        """M_phi's query clip (``inverse_dynamics.query_clip``, or the label probe's, times the mean
        training step: ``step_norm``, a running mean of the displacement norms of every row M_phi trained on)."""
        qc = self.query_clip
        return None if qc is None or self.step_norm[0] == 0 else float(qc * self.step_norm[1])

    # -- the writes, durable before a checkpoint; pruned after it --------------------------------------
    def _after_checkpoint(self) -> None:
        """Once the checkpoint taken after generation ``g`` is on disk (the next generation starts only
        then), drop the shards and data parts that neither it nor the older kept checkpoints read: a
        re-run of ``g+1`` reads ``g`` (M_phi) and ``g-history+2 .. g`` (D_i). Deleting before the
        checkpoint is durable would lose what the previous one needs if the run dies in between."""
        if self._saved is None:
            return
        g, oldest_parts = self._saved
        self._saved = None
        old = [x for x in list_generations(self.traj_root)
               if x <= g + 1 - max(self.sh.history, 2) - self._ckpt_margin]
        if old:
            delete_generations(self.traj_root, old)
        for track, oldest in zip(self._tracks, oldest_parts):
            track.parts.delete_before(oldest - self._ckpt_margin)

    def _join_writes(self) -> float:
        """Wait for the background shard writes; returns their total time (raises their errors)."""
        done, self._writes = self._writes, []
        t = float(sum(f.result() for f in done))
        self._write_time += t
        return t
