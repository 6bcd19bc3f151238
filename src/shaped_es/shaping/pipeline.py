"""Master side of the paper's Algorithm 1 (``--method shaped``), as a guide of the generation loop.

Per generation ``g`` (timeline; ``||`` = concurrently)::

    begin_generation(g):  M_phi.add(trajectories of g-1)  ->  train M_phi in a thread  ||  workers roll
                          out Theta_g and write their shards (rollout_and_store)
    strategy.tell(R_g)    -> mu_{g+1}
    after_tell(g):        join M_phi; workers label D_i with M_phi and clone theta_i -> theta*_i;
                          Delta = (Theta* - mu_{g+1}) / eta  (paper Eq. for Delta_g);  strategy.guide(Delta)
                          -> the next ask samples from Sigma = alpha/n I + (1 - alpha)/k U U^T (scaled by n)

M_phi therefore lags one generation behind the rollouts (it trains on g-1 while g runs), exactly as the
paper overlaps its training with the workers. Labels are taken only after the training thread has
joined, so results do not depend on timing.
"""

from __future__ import annotations

import functools
import threading
import time

import numpy as np

from shaped_es import seeding
from shaped_es.config import ConfigError, RunConfig
from shaped_es.envs.core import POSITION_KEY, WAYPOINT_KEY
from shaped_es.guides import NoGuide
from shaped_es.policies import MLPSpec
from shaped_es.rollout import make_env
from shaped_es.shaping.cloning import CloningConfig
from shaped_es.shaping.inverse_dynamics import InverseDynamics, InverseDynamicsConfig, training_pairs
from shaped_es.shaping.surrogate import cosine, subspace_alignment, surrogate_gradients
from shaped_es.shaping.trajectories import delete_generations, list_generations, read_generation
from shaped_es.shaping.worker import CloneTask, label_and_clone, rollout_and_store


def waypoint_dim(cfg: RunConfig) -> int:
    """Dimension of the env's waypoint space; one clear error if it lacks the contract."""
    env = make_env(cfg.env, cfg.env_kwargs)
    try:
        _, info = env.reset(seed=0)
    finally:
        env.close()
    if POSITION_KEY not in info or WAYPOINT_KEY not in info:
        raise ConfigError(f"--method shaped needs info['{POSITION_KEY}'] and info['{WAYPOINT_KEY}'] "
                          f"from {cfg.env} (see the README's environment contract)")
    return int(np.asarray(info[POSITION_KEY]).reshape(-1).shape[0])


METRIC_KEYS = (
    "mphi_train_loss", "mphi_test_loss", "mphi_iterations", "mphi_dataset_size", "mphi_kept_fraction",
    "clone_loss_before", "clone_loss_after", "label_std", "surrogate_rank", "surrogate_update_alignment",
    "clone_step_update_cosine", "time_mphi_s", "time_mphi_wait_s", "time_cloning_s", "time_update_s",
)


class ShapedGuide(NoGuide):
    record = True

    def __init__(self, cfg: RunConfig, spec: MLPSpec, store):
        self.cfg, self.spec, self.sh = cfg, spec, cfg.shaping
        self.traj_root = self.sh.trajectory_root or str(store.trajectories_dir)
        mp = self.sh.inverse_dynamics
        pos_dim = waypoint_dim(cfg)
        frame = mp.frame if mp.frame != "auto" else ("motion" if pos_dim == 2 else "world")
        self.mphi_cfg = InverseDynamicsConfig(
            hidden=tuple(mp.hidden), lr=mp.lr, batch_size=mp.batch_size,
            steps_per_generation=mp.steps_per_generation, min_return=mp.min_return,
            max_dataset=mp.max_dataset, frame=frame, seed=seeding.derive_seed(cfg.seed, seeding.SHAPING),
        )
        c = self.sh.cloning
        self.clone_cfg = CloningConfig(steps=c.steps, lr=c.lr, batch_size=c.batch_size,
                                       optimizer=c.optimizer, max_samples=c.max_samples)
        self.mphi = InverseDynamics(spec.obs_dim, pos_dim, spec.act_dim, self.mphi_cfg)
        self.step_norm = np.zeros(2)  # (count, mean) of one-step displacement norms, for query_clip
        self._thread: threading.Thread | None = None
        self._pending: dict = {}

    def rollout_fn(self):
        return functools.partial(rollout_and_store, traj_root=self.traj_root)

    # -- M_phi, concurrently with the rollouts -----------------------------------------------------
    def begin_generation(self, generation: int) -> None:
        self._pending = dict.fromkeys(METRIC_KEYS)
        self._pending.update(time_mphi_s=0.0, mphi_iterations=self.mphi.iterations,
                             mphi_dataset_size=self.mphi.dataset_size)
        if generation == 0:
            return
        data = read_generation(self.traj_root, generation - 1)
        if self.mphi.iterations > 0:  # held-out error: g-1's actual (s, dp) -> a, before training on it
            pairs = [training_pairs(tr, self.mphi_cfg.frame) for tr in data if len(tr)]
            if pairs:
                s, dp, a = (np.concatenate(x) for x in zip(*pairs))
                self._pending["mphi_test_loss"] = self.mphi.test_loss(s, dp, a)
        for tr in data:
            _, dp, _ = training_pairs(tr, self.mphi_cfg.frame)
            norms = np.linalg.norm(dp, axis=1)  # (T',)
            cnt = self.step_norm[0] + norms.size
            if norms.size:
                self.step_norm = np.array([cnt, self.step_norm[1] + (norms.sum() - norms.size *
                                                                      self.step_norm[1]) / cnt])
        stats = self.mphi.add(data)
        self._pending.update(mphi_dataset_size=stats["dataset_size"],
                             mphi_kept_fraction=stats["kept_fraction"])
        self._thread = threading.Thread(target=self._train, name="mphi-train", daemon=True)
        self._thread.start()

    def _train(self) -> None:
        t0 = time.perf_counter()
        losses = self.mphi.train()
        self._pending["mphi_train_loss"] = float(np.mean(losses)) if losses else None
        self._pending["mphi_iterations"] = self.mphi.iterations
        self._pending["time_mphi_s"] = time.perf_counter() - t0

    # -- cloning and the surrogate subspace ----------------------------------------------------------
    def after_tell(self, generation, params, results, old_mean, strategy, map_tasks) -> dict:
        t_wait = time.perf_counter()
        if self._thread is not None:
            self._thread.join()
            self._thread = None
        out = dict(self._pending, time_mphi_wait_s=time.perf_counter() - t_wait, time_cloning_s=0.0,
                   clone_cpu_time_s=0.0,
                   time_update_s=0.0, surrogate_rank=0)
        if self.mphi.iterations == 0:  # no data kept yet: this generation stays Vanilla-ES
            self._prune(generation)
            return out
        t0 = time.perf_counter()
        theta_star, outs = self._clone(generation, params, map_tasks, n_tasks=len(results))
        out["time_cloning_s"] = time.perf_counter() - t0
        out["clone_cpu_time_s"] = float(sum(o.cpu_time_s for o in outs))  # on the workers
        t1 = time.perf_counter()
        mean = np.asarray(strategy.mean, dtype=np.float64)
        if self.sh.surrogate == "paper":
            G = surrogate_gradients(theta_star, mean, self.sh.eta)  # (k, n): (Theta* - mu_{g+1}) / eta
        elif self.sh.surrogate == "clone_step":
            G = theta_star.astype(np.float64) - params  # (k, n): the cloning steps alone
        else:
            G = (theta_star.astype(np.float64) - params).mean(axis=0, keepdims=True)  # (1, n)
        strategy.guide(G)
        update = mean - np.asarray(old_mean, dtype=np.float64)  # (n,) this generation's ES step
        U = strategy.U  # (n, k') the basis the next ask samples in (QR of G, computed by guide)
        out.update(
            time_update_s=time.perf_counter() - t1, surrogate_rank=int(U.shape[1]),
            surrogate_update_alignment=subspace_alignment(U, update) if np.any(update) else None,
            clone_step_update_cosine=cosine((theta_star - params).mean(axis=0), update),
            clone_loss_before=_nanmean(np.concatenate([o.loss_before for o in outs])),
            clone_loss_after=_nanmean(np.concatenate([o.loss_after for o in outs])),
            label_std=float(np.mean([o.label_std for o in outs])),
        )
        self._prune(generation)
        return out

    def _clone(self, generation, params, map_tasks, n_tasks):
        P = params.shape[0]
        gens = list(range(max(0, generation - self.sh.history + 1), generation + 1))
        snap = self.mphi.state_dict(with_training=False)
        qc = self.sh.inverse_dynamics.query_clip
        max_disp = None if qc is None or self.step_norm[0] == 0 else float(qc * self.step_norm[1])
        seeds = np.array([seeding.derive_seed(self.cfg.seed, seeding.SHAPING, generation, m) for m in range(P)])
        tasks = [CloneTask(self.spec, params[idx], idx, seeds[idx], gens, self.traj_root, snap,
                           self.mphi_cfg, self.clone_cfg, max_disp)
                 for idx in np.array_split(np.arange(P), max(1, min(P, n_tasks)))]
        outs = map_tasks(label_and_clone, tasks)
        theta_star = np.empty_like(params)  # (P, n)
        for o in outs:
            theta_star[o.members] = o.theta_star
        return theta_star, outs

    def _prune(self, generation: int) -> None:
        """Drop shards no generation will read again, even one re-run after a crash before its checkpoint:
        a re-run of ``g`` reads ``g-1`` (M_phi) and ``g-history+1 .. g`` (D_i)."""
        old = [g for g in list_generations(self.traj_root) if g <= generation - max(self.sh.history, 2)]
        if old:
            delete_generations(self.traj_root, old)

    # -- checkpoint ---------------------------------------------------------------------------------
    def state_dict(self) -> dict[str, np.ndarray]:
        st = {f"mphi/{k}": v for k, v in self.mphi.state_dict(with_training=True).items()}
        st["step_norm"] = self.step_norm
        return st

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        self.mphi.load_state_dict({k[5:]: v for k, v in state.items() if k.startswith("mphi/")})
        self.step_norm = np.asarray(state["step_norm"], dtype=np.float64)

    def close(self) -> None:
        if self._thread is not None:
            self._thread.join()
            self._thread = None


def _nanmean(x: np.ndarray) -> float | None:
    x = x[np.isfinite(x)]
    return float(x.mean()) if x.size else None
