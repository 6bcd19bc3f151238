"""A benchmark's verdict in the terminal: one line per method against the reference, from its summary.

A new user's quadrotor benchmark ended on a JSON line of file paths; whether the shaped runs had gained
anything, and at what price, was in ``report.md`` only. These lines say it where the run ends: seeds that
reached the threshold, generations and wall time to it (ratios of censored means, with the summary's
bootstrap intervals), the late test reward's IQM, and for a shaped method the candidates accepted.
"""

from __future__ import annotations

from shaped_es.benchmark.numbers import ratio_text
from shaped_es.benchmark.summary import FALLBACK_SOURCE

BASELINE = "vanilla"  # what each other method is set against (the first method where it did not run)


def verdict_lines(summary: dict, where: str | None = None) -> list[str]:
    """``summary`` (``summary.json``'s content) -> one line per method against the baseline (Vanilla-ES where it
    ran, else the first method); no line where fewer than two methods ran. ``where``: the benchmark directory
    (or the report's runs), named in the hint where too few runs reached the threshold for its ratios to tell."""
    methods = summary.get("methods") or {}
    if len(methods) < 2:
        return []
    ref = BASELINE if BASELINE in methods else next(iter(methods))
    thr = (summary.get("threshold") or {}).get("value")
    r = methods[ref]
    lines = []
    for name, m in methods.items():
        if name == ref:
            continue
        reached = f"{m['successes']}/{m['seeds']} vs {r['successes']}/{r['seeds']} seeds reached {thr:g}"
        late = (f"late test reward IQM {m['late_test_reward_iqm']:.2f} vs {r['late_test_reward_iqm']:.2f}"
                if m.get("late_test_reward_iqm") is not None and r.get("late_test_reward_iqm") is not None else None)
        ratios = (summary.get("ratios_to_threshold") or {}).get(name, {}).get(ref, {})
        # fewer than half the runs of either side reached it: the ratios to it compare mostly whole runs' lengths
        # (two new users' bodies, 2/10 and 0/10: "wall time to it 1.52x" read as a price where shaped ended at
        # twice Vanilla-ES's reward); the late reward leads instead, the line's first number (a new user's crane
        # read "1/10 vs 0/10 seeds reached" first and took it for the verdict)
        few = 2 * m["successes"] < m["seeds"] and 2 * r["successes"] < r["seeds"]
        parts = [f"{name} vs {ref}: " + (f"{late}; {reached}" if few and late else reached)]
        if few:
            parts.append(("neither reached it" if not (m["successes"] or r["successes"]) else
                          "too few runs reached it for ratios to it to tell")
                         + (f" ({_lower_bar(where, thr)})" if where else ""))
        elif m["successes"] or r["successes"]:
            if ratios.get("generations"):
                parts.append(f"generations to it {ratio_text(ratios['generations'])}")
            if ratios.get("wall_time_s"):
                parts.append(f"wall time to it {ratio_text(ratios['wall_time_s'])}")
            if ratios.get("generations") or ratios.get("wall_time_s"):  # the ratios' note, beside them
                parts[-1] += "".join(f" {note}" for note in _censored(name, m, ref, r))
        if m.get("wall_time_s") and r.get("wall_time_s"):
            parts.append(f"whole runs' wall time {m['wall_time_s'] / r['wall_time_s']:.2f}x")
        if late and not few:
            parts.append(late)
        sh = m.get("shaping")
        if sh and sh.get("candidates_judged"):
            none = sh.get("runs_without_acceptance") or 0
            parts.append(f"candidates accepted {sh['candidates_accepted']} of {sh['candidates_judged']}"
                         + (f" ({none} of {sh['runs']} runs none: {ref}'s own steps there)" if none else ""))
        lines.append("; ".join(parts))
    if (summary.get("threshold") or {}).get("source") == FALLBACK_SOURCE:
        lines.append(f"{thr:g} is the best baseline's final mean (the env registers no reward_threshold and no "
                     f"--threshold was given): where no baseline learned it is no bar, so read the late test "
                     f"reward; give --threshold R or register reward_threshold (check-env suggests one from a "
                     f"waypoint_controller)")
    return lines


def _lower_bar(where: str, thr: float) -> str:
    """The hint of a threshold most runs missed: the report at a lower bar."""
    return f"shaped-es report {where} --threshold T --out report_T/report.md compares them at a bar T below {thr:g}"


def _censored(name: str, m: dict, ref: str, r: dict) -> list[str]:
    """What the ratios to the threshold are where runs did not reach it (counted at their whole length, the
    censored means'): upper bounds where only ``ref``'s did not, lower bounds where only ``name``'s did (a new
    user's arm read "wall time to it 1.94x" as a price where Vanilla-ES had reached it on no seed)."""
    short_m, short_r = m["seeds"] - m["successes"], r["seeds"] - r["successes"]
    if not (short_m or short_r):
        return []
    if short_m and short_r:
        return ["(unsolved runs on both sides count their whole length: the ratios are rough)"]
    who, n, bound = (ref, short_r, "upper") if short_r else (name, short_m, "lower")
    runs = "1 unsolved run counts its" if n == 1 else f"{n} unsolved runs count their"
    return [f"({who}'s {runs} whole length: the ratios are {bound} bounds)"]
