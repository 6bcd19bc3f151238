"""What the label probe (``guides/label_probe.py``) tries, and the names it gives each try.

A variant is ``(frame, query_clip, chunk)``: M_phi's displacement frame, the query's clip (times the mean
training step, the mean length of M_phi's training displacements; None: as asked) and the chunk length of its
targets (None: one-step). The incumbent (``both``, one-step targets, the query as asked, or clipped to the mean
training step where M_phi sees each step's change: :func:`clips`; ``world`` on a line, where a frame has no heading
to turn by) comes first; its name is the default every rule in ``guides/probe_choice.py`` compares against.
"""

from __future__ import annotations

CLIP = 2.0  # the clipped variants' query_clip (times the mean training step)
# where M_phi sees each step's change (``step_change``, the probe's finding of a second-order body) and the user set
# no clip, the incumbent's query_clip: the mean training step, the pace the probe's own data moved at (:func:`clips`)
STEP_CHANGE_CLIP = 1.0
FRAMES = ("both", "world")  # the frames probed in a waypoint space of 2-D or more, the incumbent first


def clip_text(query_clip: float | None) -> str:
    return "none" if query_clip is None else f"{query_clip:g}"


def variant_name(frame: str, query_clip: float | None, chunk: int | None = None) -> str:
    """``both``, ``both+clip2``, ``world+chunk4``, ``both+chunk4+clip2``."""
    base = frame if chunk is None else f"{frame}+chunk{chunk}"
    return base if query_clip is None else f"{base}+clip{query_clip:g}"


def variant_text(name: str) -> str:
    """A variant's name as its settings: ``both+chunk4+clip2`` -> ``frame=both, targets=chunk (4 steps),
    query_clip=2``."""
    base, _, clip = name.partition("+clip")
    frame, _, chunk = base.partition("+chunk")
    return f"frame={frame}" + (f", targets=chunk ({chunk} steps)" if chunk else "") + f", query_clip={clip or 'none'}"


def probe_frames(pos_dim: int) -> tuple[str, ...]:
    """The frames probed: ``both`` (the incumbent) and ``world`` in a waypoint space of 2-D or more; ``world``
    alone on a line (1-D), where the motion frame's heading is only a sign."""
    return FRAMES if pos_dim >= 2 else ("world",)


def long_variants(user_clip: float | None, long_clip: float | None, chunk: int = 0, frames=FRAMES
                  ) -> list[tuple[str, float | None, int | None]]:
    """The ``probe_clip_long`` variants, after :func:`variants`' (none where the user set a clip or it is off)."""
    if user_clip is not None or long_clip is None or long_clip == CLIP:
        return []
    return variants(float(long_clip), chunk, frames)  # every frame and targets, with that clip alone


def clips(user_clip: float | None, step_change: bool = False) -> list[float | None]:
    """The query clips probed, the incumbent's first: the user's alone; the query as asked, then :data:`CLIP`; or,
    where M_phi sees each step's change, :data:`STEP_CHANGE_CLIP` first, then the query as asked.

    A second-order body's query asks for a change of pace: unclipped, a waypoint ahead asks for the largest change
    the body makes, step after step, until it overshoots a goal it was to hold; clipped to the mean training step it
    asks for a pace, which brakes where the waypoint is near. On a new user's spacecraft attitude body the simulated
    candidates of the two differ by less than the probe can tell while the runs differ by 20 generations (10/10 at
    its threshold in 9.6 generations against 3/10), so the clip is the incumbent; on a new user's joint-space arm
    forced to see the change, the clip alone left the runs no way out (4/10 at its threshold), and beside the query
    as asked its test replaced it on 4 of 10 seeds (9/10; docs/benchmarks/second_order_clip_v34)."""
    if user_clip is not None:
        return [user_clip]
    return [STEP_CHANGE_CLIP, None] if step_change else [None, CLIP]


def variants(user_clip: float | None, chunk: int = 0, frames=FRAMES, step_change: bool = False
             ) -> list[tuple[str, float | None, int | None]]:
    """The probed ``(frame, query_clip, chunk)`` triples, the incumbent (``both``, one-step targets, the first of
    :func:`clips`) first; a clip the user set is kept; with ``chunk`` > 0 each also with M_phi on chunk targets."""
    clips_ = clips(user_clip, step_change)
    return [(f, c, k) for k in ([None, chunk] if chunk else [None]) for f in frames for c in clips_]
