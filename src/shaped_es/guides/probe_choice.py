"""How the label probe (``guides/label_probe.py``) chooses among its variants, from the returns it measured.

Every rule compares paired episodes (the same seeds for every variant): labels driving the body step by step
(:func:`beats`, two paired standard errors), simulated candidates, whose returns are heavy-tailed
(:func:`clone_beats`, a signed-rank test and a share of the return spread), the frame's choice
(:func:`choose`) and the extensions the probe offers on top of it, chunk targets and a longer clip
(:func:`choose_targets`). The measurements behind each rule are in ``label_probe.py``'s docstring and
``docs/shaped-results.md``.
"""

from __future__ import annotations

import numpy as np

from shaped_es.guides.clone_probe import ROUNDS
from shaped_es.guides.probe_variants import variant_text

CLONE_P = 0.05  # a simulated candidate beats another at this one-sided signed-rank p-value ...
MIN_SHARE = 0.05  # ... and by this share of the spread of the probe's returns


def paired(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """``(mean, standard error)`` of the paired per-episode differences ``a - b`` (same seeds)."""
    diff = np.asarray(a, np.float64) - np.asarray(b, np.float64)  # (E,)
    se = diff.std(ddof=1) / np.sqrt(diff.size) if diff.size > 1 else np.inf
    return float(diff.mean()), float(se)


def beats(a: np.ndarray, b: np.ndarray) -> tuple[bool, float]:
    """``(a beats b, mean gain)``: the mean paired difference ``a - b`` exceeds two standard errors."""
    mean, se = paired(a, b)
    return mean > 2 * se, mean


def clone_beats(a: np.ndarray, b: np.ndarray, scale: float) -> tuple[bool, float]:
    """``(a beats b, mean gain)`` for the simulated candidates' returns, whose episodes are heavy-tailed
    (a clone that drives well on most seeds and crashes on one): a one-sided Wilcoxon signed-rank test of
    the paired differences at :data:`CLONE_P`, and a mean gain of at least :data:`MIN_SHARE` of ``scale``
    (the spread of every return the probe saw: a consistent 0.25 on a task whose returns span 90 is no
    better candidate)."""
    gain, p = _clone_test(a, b, scale)
    return bool(p is not None and p < CLONE_P), gain


def _clone_test(a: np.ndarray, b: np.ndarray, scale: float) -> tuple[float, float | None]:
    """``(mean gain of a over b, the signed-rank p-value)``; p None where the gain is below :data:`MIN_SHARE` of
    ``scale`` or every paired difference is zero (no test: ``a`` does not beat ``b``)."""
    diff = np.asarray(a, np.float64) - np.asarray(b, np.float64)  # (E,)
    gain = float(diff.mean())
    if gain < MIN_SHARE * scale or not np.any(diff != 0):
        return gain, None
    return gain, signed_rank_greater(diff)


def signed_rank_greater(diff: np.ndarray) -> float:
    """The one-sided (``greater``) Wilcoxon signed-rank p-value of ``diff`` ``(E,)``, exact: the share of the
    2^m sign assignments of its m nonzero differences' ranks (ties get their mean rank; zeros are dropped,
    Wilcoxon's rule) whose positive rank sum is at least the observed one.

    Written here rather than ``scipy.stats.wilcoxon``, whose import costs every shaped run ~1 s at its start
    (more than a cheap body's whole probe of some envs). For the probe's 10 episodes it is SciPy's p-value
    (its exact distribution without ties or zeros, its exhaustive permutation test with them; tested against
    it); with ties or zeros past 13 episodes SciPy switches to a normal approximation, this stays exact."""
    d = np.asarray(diff, np.float64).ravel()
    d = d[(d != 0) & ~np.isnan(d)]  # (m,)
    if d.size == 0:
        return 1.0
    _, inv, cnt = np.unique(np.abs(d), return_inverse=True, return_counts=True)
    ends = np.cumsum(cnt)  # each tie group's last rank
    ranks2 = (2 * ends - cnt + 1)[inv.ravel()]  # (m,) twice each mean rank: integers
    observed = int(ranks2[d > 0].sum())
    counts = np.zeros(int(ranks2.sum()) + 1)  # counts[t]: sign assignments whose positive doubled sum is t
    counts[0] = 1.0
    for r in ranks2:
        counts[r:] = counts[r:] + counts[:-r]  # the sum is a new array before it is written back
    return float(counts[observed:].sum() / counts.sum())


def _closest(clones: dict[str, np.ndarray], incumbent: str, scale: float) -> str:
    """`` (closest: both+clip2's 4.18 against -0.89, signed-rank p 0.06, needs < 0.05)``: the simulated candidate
    with the best mean above the incumbent's, and what kept it out (a new user read the choice as arbitrary);
    ``""`` where none is above."""
    own = float(np.mean(clones[incumbent]))
    name = max(clones, key=lambda k: float(np.mean(clones[k])))
    if name == incumbent or float(np.mean(clones[name])) <= own:
        return ""
    _, p = _clone_test(clones[name], clones[incumbent], scale)  # what clone_beats asked
    if p is None:
        # "(0.57)" beside "the probe's return spread" read as the spread itself (a new user's pusher): say what it is
        why = f"a gain below {MIN_SHARE:.0%} of the probe's return spread {scale:.2f} ({MIN_SHARE * scale:.2f})"
    else:
        why = f"signed-rank p {p:.3g}, needs < {CLONE_P:g}"  # 0.0508 read "0.05" with two decimals
    return f" (closest: {variant_text(name)}'s {np.mean(clones[name]):.2f} against {own:.2f}, {why})"


def best_beating(returns: dict[str, np.ndarray], incumbent: str, test=beats) -> tuple[str, float]:
    """The variant that beats ``incumbent`` by the most (by ``test``), and by how much; ``(incumbent, 0)``
    if none does."""
    best, best_gain = incumbent, 0.0
    for name, r in returns.items():
        ok, gain = test(r, returns[incumbent])
        if ok and gain > best_gain:
            best, best_gain = name, gain
    return best, best_gain


def choose(returns: dict[str, np.ndarray], incumbent: str, zero: np.ndarray,
           clones: dict[str, np.ndarray] | None = None) -> tuple[str, str]:
    """``(variant, reason)``: the variant whose simulated candidate (``clones``: the mean's clone after
    ``clone_probe.ROUNDS`` DAgger rounds) beats the incumbent's by the most, by two paired standard
    errors; else the incumbent, unless zero action drives the body better than its labels (by two paired
    standard errors): then the variant whose labels beat the incumbent's by the most, if one does."""
    closest = ""
    if clones:
        seen = np.concatenate([np.ravel(v) for v in (*returns.values(), *clones.values(), zero)])  # every return
        scale = float(seen.max() - seen.min()) if seen.size else 0.0
        best, gain = best_beating(clones, incumbent, lambda a, b: clone_beats(a, b, scale))
        if best != incumbent:
            return best, (f"its simulated candidate (the initial mean cloned toward its labels, {ROUNDS} DAgger "
                          f"rounds) beats the default's ({variant_text(incumbent)}) by {gain:.2f} return "
                          f"(signed-rank p < {CLONE_P:g}, at least {MIN_SHARE:.0%} of the probe's return spread)")
        closest = _closest(clones, incumbent, scale)
    worse, by = beats(zero, returns[incumbent])
    if not worse:
        # "the default's", not "its own": a new user read "its own" as the variant's
        return incumbent, (f"the default: no variant's simulated candidate clearly beats the default's{closest}, "
                           f"and zero action does not beat its labels (driving the body step by step) by 2 paired "
                           f"standard errors")
    best, best_gain = best_beating(returns, incumbent)
    if best == incumbent:
        return best, (f"the default: no variant's simulated candidate clearly beats the default's{closest}; zero "
                      f"action beats its labels by {by:.2f} return, and no variant beats the default's labels by 2 "
                      f"paired standard errors")
    return best, (f"zero action beats the default's labels ({variant_text(incumbent)}) by {by:.2f} return; "
                  f"{variant_text(best)} beats the default's labels by {best_gain:.2f} (> 2 paired standard errors)")


def choose_targets(returns: dict[str, np.ndarray], incumbent: str, zero: np.ndarray, clones: dict[str, np.ndarray],
                   ranking: list[str], long_tag: str | None = None) -> tuple[str, str]:
    """:func:`choose` over every variant; a variant of an extension the probe offers (chunk targets, ``+chunk``;
    the ``probe_clip_long`` clip, ``long_tag`` such as ``+clip4``) stands only where the labels of the variant
    chosen without that extension (for chunk targets: without either) do not drive the body better than its
    own (by two paired standard errors: there the base labels already show the action); a chunk variant also only where it is ``best``, the
    simulated candidate with the best mean return of all (``ranking``: every variant's and shooting horizon's
    name, best first, ``probe_candidate.rank``), and a longer clip only where its own labels drive the body
    better than zero action (two paired standard errors: a longer query asks labels for a larger move, which
    is worth asking only of labels that move the body at all) and differ from the unclipped variant's (else
    the clip never bound, and its candidate's win is the clone's seed noise); else the choice without it (the same rules,
    among the candidates left). On the kart the chunk variants beat ``both``'s clearly, the shooting candidate
    drove far better, and the runs that took them were slower; on UR5Reach-v0's seeds 0 and 1 the one-step
    labels drove the arm clearly better, and the runs that took chunk targets ended 19-38 return lower; on the
    Reacher's seeds 0, 2 and 3 every variant's labels drove the arm worse than zero action and the runs that
    took a clip of 4 were slower (18 -> 22, 18 -> unsolved, 22 -> 40; docs/benchmarks/probe_chunk_v15)."""
    best = ranking[0] if ranking else None
    name, reason = choose(returns, incumbent, zero, clones)
    for tag in ("+chunk", long_tag):
        if not tag or tag not in name:
            continue
        one, why = choose_targets({k: v for k, v in returns.items() if tag not in k}, incumbent, zero,
                                  {k: v for k, v in clones.items() if tag not in k},
                                  [k for k in ranking if tag not in k], long_tag)
        base = one
        if tag == "+chunk":
            if long_tag:  # chunk targets are judged as without the longer clip (UR5Reach-v0's seed 1: the choice
                # without chunk variants was a clip-4 variant whose labels drove worse than both's, and the chunk
                # variant that both's labels beat by 18 stood; the run ended 19 return lower)
                base = choose_targets({k: v for k, v in returns.items() if tag not in k and long_tag not in k},
                                      incumbent, zero,
                                      {k: v for k, v in clones.items() if tag not in k and long_tag not in k},
                                      [k for k in ranking if tag not in k and long_tag not in k])[0]
            own_ok = best is not None and "+chunk" in best
            own = "where their candidate is the best of all" + (
                "" if best is None else f", here the shooting labels' ({best.split(':')[1]} steps)"
                if best.startswith("shoot:") else f", here {best}'s")
        else:
            moves, over = beats(returns[name], zero)
            # a clip that never binds on the probe's episodes leaves the labels as they were: the variant is the
            # unclipped one cloned on another seed stream, and its win a second draw of the clone's noise
            # (UR5Reach-v0's seed 17: both+chunk4+clip4's labels were both+chunk4's to the last digit, its
            # candidate 44.7 against 34.6; the run took 30 generations against 13)
            plain = name.replace(tag, "")
            binds = plain not in returns or not np.array_equal(returns[name], returns[plain])
            own_ok = bool(moves) and binds
            own = (f"where its labels drive the body better than zero action (here by {over:.2f}, within 2 paired SE)"
                   if binds else f"where the clip changes the labels (here {plain}'s, to the last digit)")
        drives, by = beats(returns[base], returns[name])
        if own_ok and not drives:
            continue
        what = "chunk targets stand" if tag == "+chunk" else f"a query clip of {tag[5:]} stands"
        if own_ok:
            own = (f"where the labels chosen without it do not drive the body better (here {variant_text(base)}'s, "
                   f"by {by:.2f})")
        return one, f"{why}; {name}'s simulated candidate did beat the default's clearly, but {what} only {own}"
    return name, reason


def unjudged(zero: np.ndarray, simulated: dict[str, np.ndarray]) -> bool:
    """Whether the probe's numbers cannot judge the label sources: no simulated candidate (``simulated``, name ->
    ``(E,)``: every variant's and every shooting horizon's) beats zero action's returns ``zero`` ``(E,)`` by two
    paired standard errors. Seen where zero action is a safe policy (a hovering drone, an arm held still) and
    every candidate cloned from the crashing or flailing initial mean loses to it, the sources that later pay
    too."""
    return bool(simulated) and not any(beats(v, zero)[0] for v in simulated.values())


def keep_shoot(shoot: np.ndarray, zero: np.ndarray, clones: dict[str, np.ndarray], keep_best: bool = True,
               keep_unjudged: bool = False, tried: dict[str, np.ndarray] | None = None) -> bool:
    """Whether a run keeps the shooting rival: its simulated candidate's returns ``shoot`` ``(E,)`` beat zero
    action's ``zero`` ``(E,)`` by two paired standard errors; or (``keep_best``) its mean is above every
    variant's simulated candidate's (``clones``, name -> ``(E,)``); or (``keep_unjudged``) no simulated candidate
    (the variants' ``clones`` and every shooting horizon's, ``tried``) beats zero action: :func:`unjudged`. The
    second: on a body whose zero action is a safe policy (a hovering drone) every learned candidate loses to it
    at generation 0; the shooting labels' then drove the new user's drone to the threshold in 7-29 generations
    where the runs that dropped them solved no seed in 30 (``docs/benchmarks/shoot_keep_best_v17``). The third:
    there the best mean is a draw among losers too (the drone's seeds where a variant's came first solved 2 of 9
    in 30 generations; ``docs/benchmarks/shoot_unjudged_v18``)."""
    if beats(shoot, zero)[0]:
        return True
    if keep_unjudged and unjudged(zero, {**clones, **(tried or {}), "shoot": shoot}):
        return True
    return bool(keep_best and clones and np.mean(shoot) > max(np.mean(v) for v in clones.values()))


def nearest_horizon(chosen: int, probed: list[int]) -> int | None:
    """The probed horizon nearest ``chosen`` in steps, other than it (the shorter on a tie); None if none."""
    others = sorted(h for h in set(probed) if h != chosen)
    return min(others, key=lambda h: abs(h - chosen)) if others else None
