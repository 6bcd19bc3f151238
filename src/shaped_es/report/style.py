"""One look for every figure: a fixed colour per method, and titles that name the env and the seeds."""

from __future__ import annotations

from collections.abc import Mapping, Sized

METHOD_COLORS = {  # the same method is the same colour in every figure
    "shaped": "#d62728",  # red: the paper's method
    "vanilla": "#1f77b4",  # blue
    "guided": "#9467bd",  # purple
    "cmaes": "#2ca02c",  # green
    "ppo": "#ff7f0e",  # orange
}
# methods outside the table (variants): tab10's rest, then tab20's light shades, so that up to 15 variants
# beside the five methods never share a colour in one figure
OTHER_COLORS = ("#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf", "#aec7e8", "#ffbb78", "#98df8a",
                "#ff9896", "#c5b0d5", "#c49c94", "#f7b6d2", "#c7c7c7", "#dbdb8d", "#9edae5")


def method_color(method: str, order: int = 0) -> str:
    """The fixed colour of a known method; unknown methods take the spare colours in ``order``."""
    return METHOD_COLORS.get(method, OTHER_COLORS[order % len(OTHER_COLORS)])


def method_colors(methods) -> dict[str, str]:
    unknown = [m for m in methods if m not in METHOD_COLORS]
    return {m: method_color(m, unknown.index(m) if m in unknown else 0) for m in methods}


def seeds_phrase(groups: Mapping[str, Sized]) -> str:
    """'3 seeds per method', or 'seeds: shaped 3, vanilla 2' when the counts differ."""
    counts = {k: len(v) for k, v in groups.items()}
    if not counts:
        return "no seeds"
    if len(set(counts.values())) == 1:
        n = next(iter(counts.values()))
        return f"{n} seed{'s' if n != 1 else ''}" + (" per method" if len(counts) > 1 else "")
    return "seeds: " + ", ".join(f"{k} {v}" for k, v in counts.items())


def figure_title(what: str, env: str, groups: Mapping[str, Sized], title: str = "") -> str:
    """'<title or env>: <what> (<seeds>)', the env named once even when ``title`` omits it."""
    head = title or env
    if env and env not in head:
        head = f"{head} ({env})"
    return f"{head}: {what} ({seeds_phrase(groups)})" if head else f"{what} ({seeds_phrase(groups)})"
