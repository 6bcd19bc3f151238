"""What the label probe (``guides/label_probe.py``) tells a user: the run's one line on it (:func:`probe_line`)
and ``shaped-es check-env ID --labels``, the probe a shaped run with ``frame: auto`` would run, with a verdict
a user can act on."""

from __future__ import annotations

import sys

import numpy as np

from shaped_es.guides.label_probe import EPISODES, ProbeResult, drive, probe, probe_seeds, zero_labels
from shaped_es.guides.probe_choice import beats, paired
from shaped_es.guides.probe_step_change import PLAIN_FAILS, RATIO
from shaped_es.guides.probe_variants import STEP_CHANGE_CLIP, clip_text, variant_name, variant_text
from shaped_es.guides.probe_file import FILE
from shaped_es.guides.rival import probe_shooting


def probe_line(res: ProbeResult, env: str = "ENV", rivals: list[str] = (), judged: bool = True) -> str:
    """The run's one line on the probe ``res`` (every number: label_probe.json; tables: ``check-env --labels``);
    ``rivals``: the rivals' names (``rival.names``), which name a shooting rival that runs; ``judged``: whether
    the run judges the probe's best candidate at generation 0 (``shaping.mean_clone.probe_candidate``)."""
    name, h = variant_name(res.frame, res.query_clip, res.chunk), res.shoot_horizon
    default = next(iter(res.returns), name)
    d_frame, _, d_clip = default.partition("+clip")
    differs = ", ".join(([f"frame={d_frame}"] if d_frame != res.frame else [])  # the default, by what differs
                        + (["targets=one_step"] if res.chunk else [])
                        + ([f"query_clip={d_clip or 'none'}"] if d_clip != (clip_text(res.query_clip)
                                                                         if res.query_clip else "") else []))
    why = ("the default choice" if name == default else f"beat the default, {differs}"
           if res.reason.startswith("its") else f"the default's labels, {differs}, lost to zero action")
    if res.step_change:  # why the default clips to 1 (a new user saw query_clip=1 and no reason for it)
        why += "; M_phi sees each step's change, so the default clips to the mean training step"
    own, what = (res.clones, "its candidate") if res.clones.get(name) else (res.returns, "labels")
    zero, own = res.zero_action, own.get(name)
    score = ""
    if own and zero:
        below = beats(np.array(zero), np.array(own))[0]  # by two paired standard errors
        # below zero action is said, not read as a verdict: the Reacher's and the kart's paying runs start so
        score = (f": {what} {np.mean(own):.2f}, below zero action's {np.mean(zero):.2f}" if below
                 else f": {what} {np.mean(own):.2f} vs zero action {np.mean(zero):.2f}")
        best = _best_text(res, name)
        # a new user read "below zero action" as broken labels, a line before the probe's best candidate won at
        # generation 0; another read the two candidates' numbers as contradictory: the best is named either way
        if best:
            score += f"; the probe's best: {best}, " + ("judged at generation 1" if judged else
                                              "not judged (shaping.mean_clone.probe_candidate=false)")
    # "; another is" read as cryptic (a new user): say which beats zero action and what that allows
    lost = "" if res.shoot_on else ", not above zero action" + (
        ", which another candidate beats, so the probe can judge" if _drop_text(res) else "")
    shoot = (f"; shooting rival {'kept' if res.shoot_on else 'dropped'}{f' ({h} steps{lost})' if h else ''}"
             if res.shoot and not any(n.startswith("shooting") for n in rivals) else "")
    if kept_below_zero(res) and any(n.startswith("shooting") for n in rivals):
        shoot = ("; no candidate clearly beats zero action (the probe cannot judge): the shooting rival runs"
                 if res.unjudged() else "; the shooting candidate is not clearly above zero action but above every "
                 "variant's: its rival runs")
    return (f"labels: {variant_text(name)} ({why}){score}{shoot}"
            + (f"; rivals: {', '.join(_merged(list(rivals)))}" if rivals else "")
            + f"; see {FILE}, shaped-es check-env {env} --labels"
            + (" --obs-norm" if res.obs_stats is not None else ""))  # as the run probed (es.obs_norm)


def _merged(rivals: list[str]) -> list[str]:
    """The rivals' names with several shooting horizons of one path score as one, shortest first: ``shooting (4
    and 8 steps, mean distance)``, ``shooting (4, 8 and 16 steps, mean distance)`` (the probe line stays short)."""
    shoot = [n for n in rivals if n.startswith("shooting (")]
    if len(shoot) < 2:
        return rivals
    parts = [n[len("shooting ("):].partition(" steps") for n in shoot]
    if len({p[2] for p in parts}) != 1:
        return rivals
    steps = sorted((p[0] for p in parts), key=int)
    return ([n for n in rivals if n not in shoot]
            + [f"shooting ({', '.join(steps[:-1])} and {steps[-1]} steps{parts[0][2]}"])


def unjudged_horizons(res: ProbeResult, mp) -> str:
    """``4, 8 and 16 steps``: the horizons the shooting rivals of a run with ``shaping.inverse_dynamics`` settings
    ``mp`` hold where the probe cannot judge (``rival.probe_shooting``, as the run's rivals)."""
    sh = probe_shooting(res, mp)
    held = sorted({h for h in (sh["shoot_horizon"], (sh["unjudged"] or (None,))[0], sh["third"]) if h})
    if not held:
        return "the configured horizon"
    return f"{', '.join(map(str, held[:-1]))} and {held[-1]} steps" if len(held) > 1 else f"{held[0]} steps"


SOURCE_TEXT = {"controller": "the env's waypoint_controller, the oracle: the perfect labels' own candidate (without the "
                             "probe's candidate or the rivals, which the learned default has: on some bodies it is "
                             "faster)",
               "reference": "a finished run's policy (shaping.reference_run)"}


def source_line(labels: str) -> str:
    """A run's one line on labels that are not M_phi's (no probe, so no probe line): where they come from."""
    return f"labels: {SOURCE_TEXT[labels]} (shaping.labels={labels}: no label probe, no rival labels)"


def _drop_text(res: ProbeResult) -> str:
    """Why a dropped shooting rival was dropped though below zero action was not enough (``shoot_unjudged``): the
    simulated candidate that beats zero action, a standing variant's or another horizon's (a new user read
    "not above zero action" where other seeds below it kept the rival)."""
    zero = np.array(res.zero_action)
    sims = {**{variant_text(k): v for k, v in res.standing().items()},
            **{f"shooting, {h} steps": v for h, v in res.shoot_tried.items()}}
    above = {k: float(np.mean(v)) for k, v in sims.items() if len(v) == len(zero) and beats(np.array(v), zero)[0]}
    if not above:
        return ""
    name = max(above, key=above.get)
    # "where shooting, 32 steps's simulated candidate is (1.03)" read as garbled (a new user's pusher)
    return f": the simulated candidate of {name} beats zero action ({above[name]:.2f}), so the probe can judge"


def kept_below_zero(res: ProbeResult) -> bool:
    """The shooting rival runs though its simulated candidate is not above zero action: it is the best of every
    simulated candidate (``shoot_keep_best``), or none is above zero action (``shoot_unjudged``, then
    ``res.unjudged()``; ``guides/label_probe.py``)."""
    return bool(res.shoot_on and res.shoot and res.zero_action
                and not beats(np.array(res.shoot), np.array(res.zero_action))[0])


def _best_text(res: ProbeResult, chosen: str) -> str:
    """``shooting 16 steps 8.34``: the probe's best simulated candidate where it is another than ``chosen``'s and
    scores above zero action's mean; ``""`` otherwise."""
    name = res.candidate
    if not name or name == chosen or not res.zero_action:
        return ""
    h = name.partition(":")[2] if name.startswith("shoot:") else None
    vals = _candidate_returns(res, name)
    if not vals or np.mean(vals) <= np.mean(res.zero_action):
        return ""
    return f"{f'shooting {h} steps' if h else name} {np.mean(vals):.2f}"


def candidate_line(res: ProbeResult, won: bool, returns: tuple | None = None) -> str:
    """What became of the probe's best simulated candidate (guides/probe_candidate.py), judged beside generation
    0: its labels, its mean return on the probe's episodes, ``won``; ``returns``: (its return, the initial mean's,
    generation 0's best member's) on the population's episodes, and optionally (its mean paired gain over the mean
    on every episode both ran, their count): they say which test it failed (a new user's blimp read "lost to the
    initial mean" where it had beaten the mean by 5 and lost to a member; another's read "lost to the initial mean
    (0.12 against 0.15)", two episodes' returns, where it had gained +0.42 over the 6 paired ones the rule tests);
    ``""`` where the probe kept none."""
    if res.candidate is None:
        return ""
    rest = "not counted by the back-off (it shows in labels A/J), the run goes on as without it"
    cand, mean, best = returns[:3] if returns is not None else (None, None, None)
    gain, n = returns[3:5] if returns is not None and len(returns) >= 5 else (None, None)
    vs_mean = (f"{signed(gain)} over its {n} paired episodes" if gain is not None
               else f"{cand:.2f} against {mean:.2f}" if returns is not None else "")
    beat_mean = (gain > 0) if gain is not None else (returns is not None and cand > mean)
    if won:
        verdict = ("won: it is the search's mean now (its test reward shows from the next generation's test, on "
                   "the test episodes, not the probe's)")
    elif not beat_mean:
        verdict = "lost to the initial mean" + (f" ({vs_mean})" if vs_mean else "") + f": {rest}"
    elif not cand > best:
        verdict = (f"beat the initial mean ({vs_mean}) but not generation 1's best member ({cand:.2f} against "
                   f"{best:.2f} on the population's episodes; a jump must beat what the search sampled around the "
                   f"mean): {rest}")
    else:
        verdict = (f"beat the initial mean ({vs_mean}) but not by the acceptance rule (shaping.mean_clone.accept: "
                   f"the paired gain must exceed its standard error): {rest}")
    return f"the label probe's best simulated candidate ({candidate_what(res)}) {verdict}"


def signed(x: float) -> str:
    """``+0.42``; a gain too small for two decimals keeps its sign's digit (``+0.0004``: a new user read "beat
    the initial mean (+0.00 ...)" as a tie called a win)."""
    return f"{x:+.2f}" if x == 0 or abs(x) >= 0.005 else f"{x:+.1g}"


def candidate_what(res: ProbeResult) -> str:
    """``the shooting labels', actions held 8 steps, 7.91 on the probe's episodes`` (or ``the labels of frame=world,
    query_clip=none, ...``): whose the probe's best
    simulated candidate is, and its mean return."""
    name = res.candidate or ""
    if name.startswith("shoot:"):
        h = name.partition(":")[2]
        what = f"the shooting labels', actions held {h} steps"
        if (res.shoot_on and res.shoot_horizon is not None and str(res.shoot_horizon) != h
                and not res.unjudged()):  # (where it cannot judge, the rivals hold several horizons) a new user read the
            # probe line's rival horizon and this one as a contradiction: the rival's horizon needs a clear win
            what += (f" (best by its mean; the run's shooting rival holds {res.shoot_horizon} steps, which {h} did not "
                     "beat clearly)")
    else:
        what = f"the labels of {variant_text(name)}"  # not "query_clip=4's": a possessive on a number reads badly
    vals = _candidate_returns(res, name)
    return what + (f", {np.mean(vals):.2f} on the probe's episodes" if vals else "")


EXTENSION_TEXT = {"+chunk": "chunk targets"}  # a passed-over extension's words; a clip's: "query clip of 4"


def pick_reason(res: ProbeResult, clip_set: bool = False) -> str:
    """The probe's reason as check-env's pick line gives it (``clip_set``: the user set ``query_clip``). Where M_phi
    sees each step's change and the default clips to 1, it says so where the default is first named (a new user met
    the reason three lines below); where the closest variant carries an extension passed over (``res.passed``), it
    says so (a new user saw world+clip4 named closest and generation 1's candidate another, world)."""
    reason, default = res.reason, next(iter(res.returns), "")
    if res.step_change and not clip_set and default.endswith(f"+clip{STEP_CHANGE_CLIP:g}"):
        why = "M_phi sees each step's change, so clip 1, the mean training step"
        reason = (f"the default ({why}):{reason[len('the default:'):]}" if reason.startswith("the default:")
                  else reason.replace(f"({variant_text(default)})", f"({variant_text(default)}; {why})", 1))
    for name in res.clones:
        tags = [t for t in res.passed if t in name]
        start = reason.find(f"(closest: {variant_text(name)}'s ")
        if not tags or start < 0:
            continue
        depth, end = 0, start  # the closest's parenthesis, its own parentheses inside
        for end in range(start, len(reason)):
            depth += {"(": 1, ")": -1}.get(reason[end], 0)
            if depth == 0:
                break
        lacks = " and no ".join(EXTENSION_TEXT.get(t, f"query clip of {t[5:]}") for t in tags)
        reason = (reason[:end] + f"; passed over, as the choice has no {lacks}: a run's first candidate is "
                  "chosen without it" + reason[end:])
        break
    return reason


def _candidate_returns(res: ProbeResult, name: str) -> list[float]:
    """A simulated candidate's per-episode returns by its name (a variant's, or ``shoot:H``; the file keeps a
    single probed horizon's as ``shoot``); ``[]`` where the probe kept none."""
    if name.startswith("shoot:"):
        h = name.partition(":")[2]
        return res.shoot_tried.get(h) or (res.shoot if str(res.shoot_horizon) == h else [])
    return res.clones.get(name, [])


def check_labels(env_id: str, env_kwargs: dict | None = None, seed: int = 0, obs_norm: bool = False) -> dict:
    """``shaped-es check-env ID --labels``: the probe a shaped run with ``frame: auto`` would run, and the
    zero-action policy on the same episodes (``obs_norm``: as with ``es.obs_norm``, ``--obs-norm``). Returns
    ``{"chosen", "returns", "zero_action", "verdict"}``."""
    from shaped_es.guides.shaped_setup import mphi_config, waypoint_dim
    from shaped_es.config import build_config
    from shaped_es.rollout import policy_spec, probe_env

    cfg = build_config({"env": env_id, "env_kwargs": env_kwargs or {}, "method": "shaped", "seed": seed,
                        "es": {"obs_norm": bool(obs_norm)}})
    env_probe = probe_env(cfg.env, cfg.env_kwargs, reset=True)
    spec, pos_dim = policy_spec(cfg, env_probe), waypoint_dim(cfg, env_probe)
    res = probe(cfg, spec, pos_dim, mphi_config(cfg, pos_dim),
                say=lambda line: print(f"shaped-es: {line}", file=sys.stderr, flush=True))  # a long probe's progress
    out = {"env": env_id, "seed": seed, "zero_action": res.zero_action}  # the run's seed seeds its probe
    if env_probe.discrete:  # a new user's grid read "beats zero action" of a moving action 0 as a verdict
        out["zero_is"] = ("zero action is action 0 here (a space of choices: a zero output's argmax is action 0 of "
                          "each choice, every bit clear of a MultiBinary); make action 0 the no-op for the lines "
                          "below to mean what they say (README: environment contract)")
    best = variant_name(res.frame, res.query_clip, res.chunk)
    gain, se = paired(res.returns[best], res.zero_action)
    horizons = unjudged_horizons(res, cfg.shaping.inverse_dynamics)
    kept = ("; the shooting rival drives above it, and a run keeps it" if not kept_below_zero(res) else
            "; no simulated candidate clearly beats zero action, so the probe cannot judge, and a run keeps the shooting rival "
            f"(its paths scored by their mean distance, at {horizons})" if res.unjudged() else
            "; the shooting rival's candidate, though not above it either, is the best simulated one, and a run "
            "keeps that rival")
    limit = min((n for n in (env_probe.time_limit, cfg.rollout.max_steps) if n), default=None)
    # a new user's lander: zero action crashed, so any labels beat it, and the verdict read as good news
    early = zero_ended_early(cfg, spec, limit, res.zero_action)
    low = (f"zero action ends early on {early} of {EPISODES} episodes (before the {limit}-step limit: a crash, a "
           f"fall)" if early is not None and 2 * early > EPISODES else "")
    if gain > 2 * se and low:
        verdict = (f"{best}'s labels beat zero action by {gain:.2f} return, but {low}: beating it says little; a "
                   f"run's candidate must beat the ES mean, which soon beats zero action too")
    elif gain > 2 * se:
        verdict = (f"{best}'s labels drive the body: they beat zero action by {gain:.2f} return (necessary, not "
                   f"enough: a run's candidate must beat the ES mean, which soon beats zero action too)")
    elif -gain > 2 * se:
        verdict = (f"{best}'s labels drive the body worse than zero action (by {-gain:.2f} return)"
                   + (kept if res.shoot_on else
                      f": its candidates may rarely win (a run then backs off; on the Reacher such labels paid "
                      f"all the same); compare {'shaping.labels=controller, ' if env_probe.controller else ''}"
                      f"--method vanilla / cmaes"))
    else:
        verdict = (f"{best}'s labels, driving the body step by step, are not clearly better or worse than zero "
                   f"action ({gain:+.2f} return, 2 standard errors {2 * se:.2f})"
                   + (kept if res.shoot_on else ": its candidates may rarely win (a run then backs off)"))
    if low and not gain > 2 * se:
        verdict += f"; and {low}, a low bar"
    details = []  # one line each, before the verdict
    if res.clones.get(best):  # the frame was chosen on this, not on the labels' own return
        details.append(f"{best}'s simulated candidate (what the frame was chosen on) "
                       f"{_against_zero(res.clones[best], res.zero_action)}")
    if res.shoot:  # the shooting rival is probed: its clone against zero action decides it
        details.append(f"the shooting labels' simulated candidate {frame_text(res)}{horizon_text(res)} "
                       f"{_against_zero(res.shoot, res.zero_action)}: a run {'keeps' if res.shoot_on else 'drops'} "
                       f"that rival" + (_drop_text(res) if not res.shoot_on else "" if not kept_below_zero(res) else
                                        f" (no simulated candidate clearly beats zero action: it runs at {horizons})"
                                        if res.unjudged() else " (its candidate is above every variant's)"))
    if res.step_change:  # guides/probe_step_change.py
        e = res.step_change_errors
        details.append("M_phi also sees each step's change from the last (shaping.inverse_dynamics.step_change"
                       + (f": held-out actions' unexplained share {e['change']:.2f} against {e['plain']:.2f} "
                          f"without it (on where the share without it is at least {PLAIN_FAILS:g} and the share with "
                          f"it at most {RATIO:g}x that), as on a body whose step is mostly the velocity it had" if
                          {"plain", "change"} <= set(e) else "") + "; the probe's default clips the query to "
                       "the mean training step: a pace the body can brake from)")
    elif {"plain", "change"} <= set(res.step_change_errors):  # auto chose off: say so (a new user's crane read
        # off only from the JSON)
        e = res.step_change_errors
        details.append(f"M_phi does not see each step's change from the last (shaping.inverse_dynamics.step_change "
                       f"auto: held-out actions' unexplained share {e['plain']:.2f} without it, {e['change']:.2f} with "
                       f"it; on only where the first is at least {PLAIN_FAILS:g} and the second at most {RATIO:g}x "
                       f"the first" + ("; above 1: worse than always predicting the mean action, on the "
                                        "probe's own steps: no verdict on the labels, whose simulated candidates "
                                        "above are what the run goes by" if
                                       max(e["plain"], e["change"]) > 1 else "") + ")")
    if res.candidate is not None:  # guides/probe_candidate.py
        details.append(f"a run judges the best simulated candidate beside generation 1, as its first candidate "
                       f"({candidate_what(res)}); a win makes it the mean")
    out["zero_action_ended_early"] = early  # of the EPISODES (None: no step limit to end before)
    out |= {"chosen": {"frame": res.frame, "query_clip": res.query_clip, "chunk": res.chunk,
                       "reason": pick_reason(res, cfg.shaping.inverse_dynamics.query_clip is not None)},
            "returns": res.returns, "clones": res.clones, "shoot": res.shoot, "shoot_on": res.shoot_on,
            "shoot_horizon": res.shoot_horizon, "shoot_tried": res.shoot_tried, "shoot_frame": res.shoot_frame,
            "shoot_frame_errors": res.shoot_frame_errors, "step_change": res.step_change,
            "step_change_errors": res.step_change_errors,
            "env_steps": res.env_steps, "seconds": res.seconds, "details": details,
            "verdict": verdict + f" (paired over {EPISODES} episodes; the probe took {res.env_steps} env steps)"}
    return out


def frame_text(res: ProbeResult) -> str:
    """``(in the waypoint frame: ...) ``, where the probe chose that frame for the shooting labels by their models'
    held-out errors (``guides/probe_shoot_frame.py``); else nothing (the world frame, as before)."""
    if res.shoot_frame != "waypoint":
        return ""
    e = res.shoot_frame_errors
    why = (f": its paths' held-out error {e['waypoint']:.2f} against the world frame's {e['world']:.2f}, as where "
           f"a body's state has no world heading" if {"world", "waypoint"} <= set(e) else "")
    return f"(in the waypoint frame{why}) "


def zero_ended_early(cfg, spec, limit: int | None, zero_action: list[float]) -> int | None:
    """How many of the probe's zero-action episodes (its seeds, its zero action) ended before ``limit`` steps,
    the env's time limit or ``rollout.max_steps``: terminated, by a crash or a fall. The probe keeps their
    returns only (``zero_action``), so they are driven again, one at a time (label_probe.drive, its steps);
    None without a limit, or where those returns are not the probe's (not its episodes)."""
    if not limit:
        return None
    seeds = probe_seeds(cfg)  # (EPISODES,)
    runs = [drive(cfg, zero_labels(spec.act_dim), "world", np.array([s])) for s in seeds]  # ((1,) return, steps) each
    if len(zero_action) != EPISODES or not np.allclose([float(r[0]) for r, _ in runs], zero_action,
                                                        rtol=1e-9, atol=1e-9):
        return None
    return int(sum(n < limit for _, n in runs))


def _against_zero(returns: list[float], zero: list[float]) -> str:
    """``scores 9.05 against zero action's -1.00 (above it by 10.05, more than 2 paired standard errors: 0.35)``,
    over the same episodes ("above it", "below it" or "not clearly different" by 2 paired standard errors; the
    margin and the bar named apart: a new user read "by more than 2 paired standard errors, 12.58" as either)."""
    gain, se = paired(returns, zero)
    side = (f"above it by {gain:.2f}, more than" if gain > 2 * se else f"below it by {-gain:.2f}, more than"
            if -gain > 2 * se else f"not clearly different: {abs(gain):.2f} apart, within")
    return (f"scores {np.mean(returns):.2f} against zero action's {np.mean(zero):.2f} ({side} 2 paired standard "
            f"errors: {2 * se:.2f})")


def horizon_text(res: ProbeResult) -> str:
    """How long the shooting labels hold an action, and why: ``(actions held 8 steps: its clone beats 4
    steps' (3.03) clearly; 16 steps 5.41)`` ("" without a probed horizon)."""
    if not res.shoot_horizon:
        return ""
    h, tried = str(res.shoot_horizon), res.shoot_tried
    if not tried:
        return f"(actions held {h} steps)"
    first = next(iter(tried))
    others = ", ".join(f"{k} steps {np.mean(v):.2f}" for k, v in tried.items() if k not in (h, first))
    if h == first:
        return f"(actions held {h} steps: no longer horizon is clearly better: {others})"
    return (f"(actions held {h} steps: its clone beats {first} steps' ({np.mean(tried[first]):.2f}) clearly"
            + (f"; {others})" if others else ")"))
