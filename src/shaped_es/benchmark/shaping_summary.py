"""What shaping did in a method's runs, for a benchmark's ``summary.json`` and ``report.md``: the candidates
judged and accepted (and which label variant's row each accepted one was: ``candidate_rival`` 0 the run's
own labels, 1 the rival frame's, 2 the servo's, 3 the shooting labels', 4 and 6 the shooting labels at a
second and third horizon (counted together as ``shoot_base``), 8 their held-goal version (``shoot_hold``);
``guides/rival.py``; 5 the label probe's candidate, judged at generation 0: blank there in runs from before that
value), their mean gain over the mean, the
generations shaping slept (``shaping_awake`` = 0), and the runs in which no candidate was ever accepted
(those runs are the ES strategy's, at shaping's price). None for a method without candidate columns."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import numpy as np

VARIANTS = {0: "own", 1: "rival_frame", 2: "servo", 3: "shoot", 4: "shoot_base", 5: "probe", 6: "shoot_base",
            8: "shoot_hold"}
GAINS = {"rival_frame": "rival_gain", "servo": "servo_gain", "shoot": "shoot_gain",  # a rival's column: it ran
         "shoot_base": "shoot_base_gain", "shoot_hold": "shoot_hold_gain"}


def _finite(m: dict, col: str) -> np.ndarray:
    v = m.get(col)
    return np.zeros(0) if v is None else np.asarray(v, np.float64)


def shaping_summary(runs: list[dict[str, np.ndarray]]) -> dict | None:
    """Pooled over ``runs`` (each a metrics column dict); None when no run has ``candidate_accepted``."""
    if not any("candidate_accepted" in m for m in runs):
        return None
    judged = accepted = runs_without = 0
    by_variant = dict.fromkeys(VARIANTS.values(), 0)
    gains, asleep = [], []
    undone = None  # jumps undone a generation later (revert_paired / revert_margin; None: no run has the column)
    ran = dict.fromkeys(GAINS, 0)  # runs in which each rival ran (the probe drops the shooting one on some)
    for m in runs:
        for key, col in GAINS.items():
            ran[key] += int(bool(np.isfinite(_finite(m, col)).any()))
        acc = _finite(m, "candidate_accepted")
        ok = np.isfinite(acc)  # (G,) generations with a judged candidate
        won = ok & (acc == 1)
        judged, accepted = judged + int(ok.sum()), accepted + int(won.sum())
        runs_without += int(not won.any())
        rival = _finite(m, "candidate_rival")
        for g in np.flatnonzero(won):
            v = int(rival[g]) if rival.size and np.isfinite(rival[g]) else 5 if rival.size and g == 0 else 0
            key = VARIANTS.get(v, f"variant_{v}")
            by_variant[key] = by_variant.get(key, 0) + 1
        if "jump_reverted" in m:
            undone = (undone or 0) + int((_finite(m, "jump_reverted") == 1).sum())
        gain = _finite(m, "candidate_gain")
        gains.append(gain[np.isfinite(gain)])
        awake = _finite(m, "shaping_awake")
        asleep.append(float((awake == 0).sum()) if awake.size else 0.0)
    g = np.concatenate(gains) if gains else np.zeros(0)
    return {"candidates_judged": judged, "candidates_accepted": accepted, "accepted_by_variant": by_variant,
            "runs_with_rival": ran,
            "mean_gain": float(g.mean()) if g.size else None,
            "generations_backed_off_mean": float(np.mean(asleep)) if asleep else 0.0,
            "runs_without_acceptance": runs_without, "runs": len(runs), "jumps_reverted": undone}


def probe_choices(dirs: list[Path]) -> dict | None:
    """What each run's label probe chose (``RUN/label_probe.json``): runs per frame (and M_phi's targets where
    they are chunks), and runs per shooting horizon (``"dropped"``: the probe dropped the shooting rival;
    ``"config"``: it was not probed). None when no run has a readable probe (a method without one, or runs from
    before it)."""
    frames, shoot = Counter(), Counter()
    for d in dirs:
        try:
            raw = (Path(d) / "label_probe.json").read_bytes()
            from shaped_es.guides.probe_file import parse  # here, for runs that probed: its modules load SciPy, Numba

            res = parse(raw)
        except (OSError, ValueError, TypeError, UnicodeDecodeError):
            continue
        clip = "" if res.query_clip is None else f", query clip {res.query_clip:g}"  # a new user missed a clip4 run
        frames[(res.frame if res.chunk is None else f"{res.frame} with chunk targets") + clip] += 1
        shoot["dropped" if res.shoot_on is False else "config" if res.shoot_horizon is None
              else f"{res.shoot_horizon} steps"] += 1
    return {"frame": dict(frames), "shoot": dict(shoot)} if frames else None


def _steps(item: tuple[str, int]) -> tuple[int, str]:
    """Horizons in the order of their steps (4 before 16), then ``config`` and ``dropped``."""
    head = item[0].split()[0]
    return (int(head), "") if head.isdigit() else (10**9, item[0])


def _count(s: dict, key: str) -> str:
    """A rival's accepted count for the report: \u2013 if it ran in no run, ``n (ran in k/N runs)`` if in some."""
    n, ran, runs = s["accepted_by_variant"].get(key, 0), s.get("runs_with_rival", {}).get(key), s["runs"]
    if ran is None or ran == runs:  # a summary from before the count, or the rival ran everywhere
        return str(n)
    return "\u2013" if ran == 0 else f"{n} (ran in {ran}/{runs} runs)"


def shaping_lines(methods: dict[str, dict], wall: dict[str, float] | None = None) -> list[str]:
    """The report's "What shaping did" section (empty without a method that judged candidates)."""
    rows = {k: s["shaping"] for k, s in methods.items() if s.get("shaping")}
    if not rows:
        return []
    out = ["## What shaping did", "",
           "Candidates judged and accepted, pooled over seeds (accepted: the label probe's candidate at generation 0 "
           "/ by the run's own labels / the rival "
           "frame's / the servo's / the shooting labels' / the shooting labels' at their other horizons where the probe "
           "cannot judge or beside a longer chosen one / their held-goal version, `rival_hold`), the mean gain of the judged candidate over the mean (return, on every "
           "episode both ran; over every judged candidate, the lost ones too, so it is often negative in runs the "
           "accepted ones carried), generations backed off (shaping asleep) per run, and runs where no candidate "
           "was ever accepted: those runs are the ES strategy's alone, at shaping's price. A rival's count is "
           "\u2013 where it ran in no run (off, or dropped by the label probe: the shooting labels where their "
           "simulated candidate is not above zero action while another simulated candidate is), and says in how many runs it ran where not all.", "",
           "| method | judged | accepted (probe / own / frame / servo / shoot / shoot base / held goal) | mean gain | backed off per run "
           "| runs with none accepted |",
           "|---|---|---|---|---|---|"]
    for k, s in rows.items():
        v = s["accepted_by_variant"]
        gain = "n/a" if s["mean_gain"] is None else f"{s['mean_gain']:.3g}"
        counts = " / ".join(_count(s, key) for key in GAINS)
        out.append(f"| {k} | {s['candidates_judged']} | {s['candidates_accepted']} ({v.get('probe', 0)} / {v.get('own', 0)} / "
                   f"{counts}) | {gain} | "
                   f"{s['generations_backed_off_mean']:.1f} | {s['runs_without_acceptance']}/{s['runs']} |")
    out.append("")
    undone = [f"{k} {s['jumps_reverted']} of its {s['candidates_accepted']}" for k, s in rows.items()
              if s.get("jumps_reverted") is not None]
    if undone:
        out += ["Accepted jumps undone a generation later, when the ES step's own mean beat the jumped one "
                "(`shaping.mean_clone.revert_paired`; the `jump_reverted` column): " + ", ".join(undone) + ".", ""]
    for k, s in rows.items():
        if s.get("label_probe"):
            p = s["label_probe"]
            # "frame (runs)": a frame's name can hold a comma and a number ("world, query clip 2"), which a bare
            # count after it garbled ("world, query clip 2 1", a new user read)
            out += [f"{k}'s label probe, runs per choice: frame " + "; ".join(f"{f} ({n})" for f, n in p["frame"].items())
                    + "; the shooting rival " + "; ".join(f"{h} ({n})" for h, n in sorted(p["shoot"].items(), key=_steps))
                    + " (each run's `label_probe.json` says why).", ""]
    for k, s in rows.items():
        if s["candidates_accepted"] == 0 and s["candidates_judged"]:
            base = next((b for b in ("vanilla", "cmaes") if wall and b in wall), None)
            price = (f", at {wall[k] / wall[base]:.2f}x {base}'s wall time per run" if base and wall.get(k)
                     and wall.get(base) else "")
            out += [f"**{k}: no candidate was accepted in any run**: its labels did not pay on this env, and "
                    f"its runs are the ES strategy's{price}. `shaped-es check-env ID --labels` shows whether "
                    "the labels drive the body at all.", ""]
    return out
