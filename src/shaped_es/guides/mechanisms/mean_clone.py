"""The clone of the search mean that the ``candidate`` and ``pair`` mechanisms share.

DAgger (Ross et al. 2011) on the search's own state distribution: the states the recent rollouts
visited (every ``record_every``-th member and every candidate, the last ``shaping.history``
generations) are labelled by the label source (``shaping/labels.py``), and the mean ``mu`` is cloned
toward the labels by ``steps`` Adam steps on minibatches of them, from ``mu`` itself:

    theta* = argmin_theta 1/M sum_t (pi_theta(s_t) - a_hat_t)^2,  started at mu     (Eq. L(theta), on mu)

With ``noise`` > 0 each step's gradient is taken under the search's own parameter noise (``s = noise * sigma``, the
strategy's ``search_scale()``: ``es.sigma`` for Vanilla-ES and Guided ES, CMA-ES's adapted step for shaped_cmaes;
``shaping/param_noise.py``), the loss ``E_z 1/M sum_t (pi_{theta + s z}(s_t) - a_hat_t)^2``, from generation
``noise_from`` on (before it a plain fit; ``docs/benchmarks/clone_noise_v28``, ``docs/benchmarks/noise_from_v29``).

With ``es.obs_norm`` the policy sees ``norm(s_t)``, the normalizer the next generation's rollouts use
(``host.obs_norm``, set by the trainer before ``after_tell``): ``pi_theta(norm(s_t)) ~ a_hat(s_t)``; the
label source still reads the raw ``s_t``.

One policy instead of the population's 64 (the paper's construction), so it costs a fraction of the
paper's cloning; the NumPy kernel of ``shaping/population_mlp.py`` runs it with a population of one.
"""

from __future__ import annotations

import numpy as np

from shaped_es import seeding
from shaped_es.shaping.cloning import CloningConfig, clone_sampled
from shaped_es.shaping.settings import MeanCloneConfig

CLONE_KEY = 1_000_003  # the seed key of the mean's clone (members use 0..P-1)


def noise_scale(cfg: MeanCloneConfig, generation: int) -> float:
    """The clone's noise at ``generation`` in units of ``es.sigma``: 0 before ``noise_from``, then ``noise``
    (with ``noise_ramp`` = R > 0, ``noise * min(1, k / R)`` for the k-th noisy generation, k = 1, 2, ...)."""
    k = generation - cfg.noise_from + 1  # 1 at noise_from
    if k <= 0:
        return 0.0
    return cfg.noise * (min(1.0, k / cfg.noise_ramp) if cfg.noise_ramp > 0 else 1.0)


def noise_line(cfg: MeanCloneConfig) -> str:
    """What a run says at its first clone fitted under the noise (after ``shaped-es: RUN: generation G: ``)."""
    ramp = f", growing to it over noise_ramp {cfg.noise_ramp} generations" if cfg.noise_ramp > 0 else ""
    return (f"the mean's clone is fitted under the search's parameter noise from here on (shaping.mean_clone.noise "
            f"{cfg.noise:g} x the search's step, from shaping.mean_clone.noise_from {cfg.noise_from} (counted from "
            f"0: the progress line's generation {cfg.noise_from + 1}, or the first shaped one after it where shaping "
            f"slept){ramp}; metrics.csv "
            f"clone_noise): the mean moves to where its population does well too; its test reward can dip for 10-25 "
            f"generations first (docs/benchmarks/noise_from_v29)")


def clone_mean(host, generation: int, theta: np.ndarray, cfg: MeanCloneConfig,
               rows=None, labels=None, key: int = CLONE_KEY) -> tuple[np.ndarray, dict]:
    """``(theta*, metrics)``: ``theta`` ``(n,)`` (the mean; with ``warm_start`` the previous clone)
    cloned toward the labels (``labels``, else ``host.labels``) of the recorded steps of generations up
    to ``generation`` (``rows``, else ``host.dagger_rows(generation, labels)``); ``theta*`` is ``theta``
    itself (and the metrics empty) without data. ``key``: the seed key of the clone's minibatches."""
    rows = host.dagger_rows(generation, labels) if rows is None else rows
    labels = host.labels if labels is None else labels
    if int(rows.lengths().sum()) == 0 or cfg.steps == 0:
        return np.asarray(theta, np.float64), {}
    seed = seeding.derive_seed(host.cfg.seed, seeding.SHAPING, generation, key)
    noise = noise_scale(cfg, generation) * host.search_sigma  # the search's own noise (its strategy's step)
    clone_cfg = CloningConfig(steps=cfg.steps, lr=cfg.lr, batch_size=cfg.batch_size, optimizer="adam",
                              max_samples=cfg.max_samples, noise=noise)
    res = clone_sampled(host.spec, np.asarray(theta, np.float32)[None], rows, labels, clone_cfg,
                        np.array([seed]), reference_fn=host.reference,
                        obs_norm=getattr(host, "obs_norm", None))  # (1, n)
    out = {"clone_loss_before": float(res.loss_before[0]), "clone_loss_after": float(res.loss_after[0]),
           "label_std": res.label_std, "clone_samples": int(res.samples[0]), "clone_noise": noise}
    if res.reference:
        out.update(mphi_fig5_test_loss=res.reference["label_ref_error"],
                   **{k: v for k, v in res.reference.items() if k != "label_ref_error"})
    return res.theta_star[0].astype(np.float64), out
