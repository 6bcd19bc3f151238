"""``shaping.mechanism = paper``: the paper's construction (Algorithm 1, Sec. III).

Every member ``theta_i`` is cloned toward the labels of its own aggregated data ``D_i`` (its slot's last
``history`` generations, DAgger style) by a few gradient steps (``shaping.cloning``), and

    Delta = (Theta* - mu_{g+1}) / eta                                        (Eq. Delta_g, eta = 0.01)

spans the next generation's Guided-ES subspace, ``Sigma = sigma^2 (alpha I + (1 - alpha) n/k U U^T)``.
``shaping.surrogate = clone_orth`` takes each cloning step ``theta*_i - theta_i`` minus its part in the
span of the generation's perturbations instead (what the labels add; ``docs/paper-construction.md``).

Where the cloning runs (``shaping.placement``): on the master, labels in one batch straight into shared
memory and the gradient steps in chunks on the idle process workers; or on the workers, each reading its
members' ``D_i`` from the trajectory store (``guides/shaped_tasks.py``). Both give the same ``theta*``.
"""

from __future__ import annotations

import numpy as np

from shaped_es import seeding
from shaped_es.guides.mechanisms import Mechanism
from shaped_es.guides.shaped_tasks import CloneTask, label_and_clone
from shaped_es.rollout import mean_returns, population_tasks, run_task
from shaped_es.shaping.cloning import CloneResult, clone_sampled
from shaped_es.shaping.surrogate import clone_steps_orthogonal, cosine, surrogate_gradients

REFERENCE_METRICS = ("mphi_fig5_test_loss", "own_ref_error", "clone_ref_error", "label_beats_own")


class PaperSubspace(Mechanism):
    name = "paper"
    metric_keys = ("clone_loss_before", "clone_loss_after", "label_std", "surrogate_rank",
                   "surrogate_update_alignment", "clone_step_update_cosine", "clone_return_gain",
                   "clone_improved_fraction")

    def after_tell(self, generation, params, fitness, extra_returns, results, old_mean, strategy,
                   map_tasks, judged=None) -> dict:
        host, sh = self.host, self.host.sh
        if not host.labels.ready:
            return {}
        n_tasks = sum(1 for r in results if r.members[0] < params.shape[0])  # the population's rollout tasks
        theta_star, res, worker_cpu = self._clone(generation, params, map_tasks, n_tasks=n_tasks)
        out = {"clone_cpu_time_s": worker_cpu, "surrogate_rank": 0}  # on the workers (0: all on the master)
        mean = np.asarray(strategy.mean, dtype=np.float64)
        if sh.surrogate == "paper":
            G = surrogate_gradients(theta_star, mean, sh.eta)  # (k, n): (Theta* - mu_{g+1}) / eta
        else:  # clone_orth
            G = clone_steps_orthogonal(theta_star, params, old_mean)  # (k, n): steps outside span(eps)
        strategy.guide(G)
        update = mean - np.asarray(old_mean, dtype=np.float64)  # (n,) this generation's ES step
        # share of the ES update inside the next ask's subspace: ||U^T v|| / ||v|| without forming U
        nu = float(np.linalg.norm(update))
        align = float(np.linalg.norm(strategy.subspace_coordinates(update)) / nu) if nu > 0 else None
        out.update(
            surrogate_rank=int(strategy.subspace_dim),
            surrogate_update_alignment=None if align is None else min(1.0, align),
            clone_step_update_cosine=cosine((theta_star - params).mean(axis=0), update),
            clone_loss_before=_nanmean(res.loss_before), clone_loss_after=_nanmean(res.loss_after),
            label_std=res.label_std,
        )
        if res.reference:
            out.update(mphi_fig5_test_loss=res.reference["label_ref_error"],
                       **{k: v for k, v in res.reference.items() if k != "label_ref_error"})
        if sh.diagnose_returns:
            out.update(self._return_gain(generation, theta_star, results, map_tasks, params.shape[0]))
        return out

    def _return_gain(self, generation, theta_star, results, map_tasks, P) -> dict:
        """Diagnostics: returns of theta* on the generation's own episode seeds, against theta's."""
        c, spec = self.host.cfg, self.host.spec
        seeds = seeding.episode_seeds(c.seed, seeding.TRAIN, generation, np.arange(P), c.rollout.episodes,
                                      c.rollout.common_seeds)  # (P, E): the generation's
        tasks = population_tasks(c.env, c.env_kwargs, spec, theta_star, seeds, len(results), generation,
                                 max_steps=c.rollout.max_steps)
        after = np.concatenate([r.returns for r in map_tasks(run_task, tasks)]).mean(axis=1)  # (P,)
        before = mean_returns(results)[:P]  # (P,)
        return {"clone_return_gain": float((after - before).mean()),
                "clone_improved_fraction": float((after > before).mean())}

    def _clone(self, generation, params, map_tasks, n_tasks) -> tuple[np.ndarray, CloneResult, float]:
        host = self.host
        P = params.shape[0]
        gens = host.history_generations(generation)
        seeds = np.array([seeding.derive_seed(host.cfg.seed, seeding.SHAPING, generation, m) for m in range(P)])
        if host.placement == "master":
            data = host.member_rows(gens, P)
            # one torch thread, as everywhere in the master: two threads were 1.7x faster on an idle
            # machine but 3x slower beside any other busy process (OpenMP spin-waits)
            fit = {"map_fit": map_tasks, "map_chunks": n_tasks} if host.fit_on_workers and n_tasks > 1 else {}
            res = clone_sampled(host.spec, params, data, host.labels, host.clone_cfg, seeds,
                                reference_fn=host.reference, shared=host.shared_rows, **fit)
            return res.theta_star, res, res.fit_cpu_time_s
        snap = host.mphi.state_dict(with_training=False) if host.mphi is not None else None
        tasks = [CloneTask(host.spec, params[idx], idx, seeds[idx], gens, host.traj_root, snap,
                           host.mphi_cfg, host.clone_cfg, host.labels_max_displacement(), host.labels.name)
                 for idx in np.array_split(np.arange(P), max(1, min(P, n_tasks)))]
        outs = map_tasks(label_and_clone, tasks)
        theta_star = np.empty_like(params, dtype=np.float32)  # (P, n)
        before, after, samples = np.empty(P), np.empty(P), np.empty(P, np.int64)
        for o in outs:
            theta_star[o.members], before[o.members], after[o.members] = (
                o.result.theta_star, o.result.loss_before, o.result.loss_after)
            samples[o.members] = o.result.samples
        weights = np.array([max(o.result.samples.sum(), 1) for o in outs], float)
        label_std = float(np.average([o.result.label_std for o in outs], weights=weights))
        res = CloneResult(theta_star, before, after, samples, label_std)
        return theta_star, res, float(sum(o.cpu_time_s for o in outs))


def _nanmean(x: np.ndarray) -> float | None:
    x = np.asarray(x, dtype=np.float64)
    x = x[np.isfinite(x)]
    return float(x.mean()) if x.size else None
