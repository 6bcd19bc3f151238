"""A benchmark's verdict in the terminal: one line per method against the reference, from its summary.

A new user's quadrotor benchmark ended on a JSON line of file paths; whether the shaped runs had gained
anything, and at what price, was in ``report.md`` only. These lines say it where the run ends: seeds that
reached the threshold, generations and wall time to it (ratios of censored means, with the summary's
bootstrap intervals), the late test reward's IQM, and for a shaped method the candidates accepted.
"""

from __future__ import annotations

from shaped_es.benchmark.markdown import ratio_text

BASELINE = "vanilla"  # what each other method is set against (the first method where it did not run)


def verdict_lines(summary: dict) -> list[str]:
    """``summary`` (``summary.json``'s content) -> one line per method against the baseline (Vanilla-ES where it
    ran, else the first method); no line where fewer than two methods ran."""
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
        parts = [f"{name} vs {ref}: {m['successes']}/{m['seeds']} vs {r['successes']}/{r['seeds']} seeds reached "
                 f"{thr:g}"]
        ratios = (summary.get("ratios_to_threshold") or {}).get(name, {}).get(ref, {})
        if m["successes"] or r["successes"]:
            if ratios.get("generations"):
                parts.append(f"generations to it {ratio_text(ratios['generations'])}")
            if ratios.get("wall_time_s"):
                parts.append(f"wall time to it {ratio_text(ratios['wall_time_s'])}")
        else:
            parts.append("neither reached it")
        if m.get("wall_time_s") and r.get("wall_time_s"):
            parts.append(f"whole runs' wall time {m['wall_time_s'] / r['wall_time_s']:.2f}x")
        if m.get("late_test_reward_iqm") is not None and r.get("late_test_reward_iqm") is not None:
            parts.append(f"late test reward IQM {m['late_test_reward_iqm']:.2f} vs {r['late_test_reward_iqm']:.2f}")
        sh = m.get("shaping")
        if sh and sh.get("candidates_judged"):
            none = sh.get("runs_without_acceptance") or 0
            parts.append(f"candidates accepted {sh['candidates_accepted']} of {sh['candidates_judged']}"
                         + (f" ({none} of {sh['runs']} runs none: {ref}'s own steps there)" if none else ""))
        lines.append("; ".join(parts))
    return lines
