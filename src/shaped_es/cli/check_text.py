"""How check-env's lines are written: one line from any text, ANSI colours and line breaks gone (:func:`_line`),
a number as ``%g`` (:func:`_num`), and the spaces line's parts: an action Box's bounds (:func:`_bounds`), a Dict
observation's keys in flattening order (:func:`_order`) and the action a zero policy output is (:func:`_zero_text`)."""

from __future__ import annotations

import re

import gymnasium as gym
import numpy as np

from shaped_es.actions import zero_action

_ANSI = re.compile(r"\x1b\[[0-9;]*m")


def _line(text: str) -> str:
    return " ".join(_ANSI.sub("", text).split())


def _num(x: float) -> str:
    return f"{float(x):g}"


def _bounds(act: gym.spaces.Box) -> str:
    """``[-1, 1]`` where every dimension has the same bounds, else each one's (``[0, 5] x [-0.3, 0.3]``; a new
    user's thrust and steering read as one range ``[-0.3, 5]``), past 6 dimensions the lowest and highest."""
    low, high = np.asarray(act.low).ravel(), np.asarray(act.high).ravel()
    if (low == low[0]).all() and (high == high[0]).all():
        return f"[{_num(low[0])}, {_num(high[0])}]"
    if low.size > 6:
        return f"[{_num(low.min())}, {_num(high.max())}] (the bounds differ per dimension)"
    return " x ".join(f"[{_num(lo)}, {_num(hi)}]" for lo, hi in zip(low, high))


def _order(space: gym.Space) -> str:
    """``: a (2), b (4), in that order``: a Dict space's keys and sizes in gymnasium.spaces.flatten's order,
    else ``""``."""
    if isinstance(space, gym.spaces.Dict):
        return ": " + ", ".join(f"{k} ({gym.spaces.flatdim(v)})" for k, v in space.spaces.items()) + ", in that order"
    return ""


def _zero_text(space: gym.Space) -> str:
    """The action a zero policy output is in a space of choices: ``0``, ``-1``, ``[0 0]``, ``[-1 -2]``."""
    return str(zero_action(space)).replace("\n", " ")
