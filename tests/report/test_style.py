"""Fixed colours per method, distinct within a figure."""

from __future__ import annotations

from shaped_es.report.style import METHOD_COLORS, method_colors


def test_known_methods_keep_their_colour_and_variants_never_share_one():
    methods = ["shaped", "own", "fast", "lean", "nocl", "total", "total-lean", "total-nocl", "hind", "vanilla",
               "cmaes", "ppo", "guided", "a", "b", "c", "d", "e", "f", "g"]  # 5 known + 15 variants
    colors = method_colors(methods)
    assert colors["shaped"] == METHOD_COLORS["shaped"] and colors["vanilla"] == METHOD_COLORS["vanilla"]
    assert len(set(colors.values())) == len(methods)
