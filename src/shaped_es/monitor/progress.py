"""Live progress for long runs: a rich bar on a terminal, a plain line otherwise (a log file, a pipe).

Off a terminal the first line comes with the first generation, the second with the next, then one every
~5% of the run. Its pace, the steps/s and the ETA, is measured from the first generation's line on: the
first generation carries the start-up (worker processes, compiled kernels, imports), so the time to it
would inflate every ETA; the first line therefore has no ETA yet. Below ~110 columns the terminal bar
drops its bar graphic and shortens its words (``gen 12/80 -3.1 test 4.2 1.2M/s 3/9 acc off 0:01:02 ETA
0:03:10``: the train and test rewards, steps/s, candidates accepted of judged and whether shaping
sleeps, elapsed, ETA), so that 80 columns fit it whole.

Steps/s is timed by the rows' own clock (``wall_time_s``: the run's wall time when each generation was
done, as ``metrics.csv`` has it), not by when a row reaches the display: rows can arrive together (a
generation's row waits for its test episodes, so the last two rows of a run are written at once), and
the display's clock would then divide a generation's steps by the milliseconds between two writes
(millions of steps/s on a run's last line). The first line gives its own generation's rate
(``gen_env_steps / gen_time_s``); rows without these clocks fall back on the display's.

The elapsed time (the plain line's ``12s``, the bar's ``0:00:12``) is the run's: ``elapsed``, what the run
had taken when the display started (the run loop passes the saved ``wall_time_s`` of a resumed run plus
this process's start-up, which holds the shaped method's label probe), plus the display's own time.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from datetime import timedelta

from rich.console import Console
from rich.progress import BarColumn, Progress, Task, TextColumn, TimeElapsedColumn, TimeRemainingColumn
from rich.text import Text

COMPACT_BELOW = 110  # terminal columns


class ProgressDisplay:
    def __init__(self, total: int, start: int = 0, enabled: bool = True, label: str = "train",
                 clock: Callable[[], float] = time.perf_counter, console: Console | None = None,
                 stream=None, elapsed: float = 0.0):
        self.total, self.enabled, self.label = total, enabled, label
        self._clock, self._stream = clock, stream
        self._t0, self._start = clock(), start
        self._before = elapsed  # seconds the run had taken when this display started (module docstring)
        self._first: tuple[float, int, int] | None = None  # (time, generations done, steps) at the first line
        self._first_wall: float | None = None  # the first line's row's wall_time_s (the run's clock)
        self._steps = 0
        self._judged = self._accepted = 0  # candidate runs: judged / accepted candidates shown so far
        self._live = enabled and (console is not None or sys.stderr.isatty())
        self._every = max(1, (total - start) // 20)
        self._bar = None
        self._compact = False
        if self._live:
            console = console or Console(stderr=True)
            # below COMPACT_BELOW columns the bar graphic goes and the figures shorten, so that the
            # generation count, steps/s and the ETA always fit (rich cuts a line's end otherwise)
            self._compact = console.width < COMPACT_BELOW
            bar = [] if self._compact else [BarColumn(bar_width=24)]
            self._bar = Progress(
                TextColumn("[bold]{task.description}"),
                *bar,
                TextColumn("gen {task.completed}/{task.total}"),
                TextColumn("{task.fields[info]}"),
                RunElapsedColumn(),
                TextColumn("ETA"),
                TimeRemainingColumn(),
                console=console,
                transient=False,
                get_time=clock,
            )
            self._bar.start()
            self._task = self._bar.add_task(label, total=total, completed=start, info="", before=elapsed)

    def _rate(self, now: float, row: dict) -> float:
        """Env steps per second since the first line, timed by the rows' ``wall_time_s`` (the first line:
        its generation's ``gen_env_steps / gen_time_s``); the display's clock for rows without them."""
        wall = _number(row.get("wall_time_s"))
        if self._first is None:
            gen_time, gen_steps = _number(row.get("gen_time_s")), _number(row.get("gen_env_steps"))
            if gen_time and gen_time > 0 and gen_steps is not None:
                return gen_steps / gen_time
        elif wall is not None and self._first_wall is not None and wall > self._first_wall:
            return (self._steps - self._first[2]) / (wall - self._first_wall)
        if self._first is None or now <= self._first[0]:
            return self._steps / max(now - self._t0, 1e-9)
        return (self._steps - self._first[2]) / (now - self._first[0])

    def eta(self, now: float, done: int) -> float | None:
        """Seconds left at the pace since the first line (None before a second line)."""
        if self._first is None or done <= self._first[1] or now <= self._first[0]:
            return None
        return (now - self._first[0]) / (done - self._first[1]) * (self.total - done)

    def update(self, generation: int, row: dict) -> None:
        if not self.enabled:
            return
        now, done = self._clock(), generation + 1
        self._steps += int(row.get("gen_env_steps", 0) or 0)
        rate = self._rate(now, row)
        test = row.get("test_reward_mean")
        labels = self._labels(row, short=self._compact)
        if self._compact:  # 80 columns: short words, so that the elapsed time and the ETA stay on the line
            test_s = "" if test in (None, "") else f" test {float(test):.1f}"
            info = f"{float(row['train_reward_mean']):.1f}{test_s} {_si(rate)}/s{labels}"
        else:
            test_s = "" if test in (None, "") else f" test {float(test):8.2f}"
            info = (f"train mean {float(row['train_reward_mean']):8.2f} max {float(row['train_reward_max']):8.2f}"
                    f"{test_s}  {rate:,.0f} steps/s{labels}")
        if self._bar is not None:
            self._bar.update(self._task, completed=done, info=info)
        elif done - self._start <= 2 or done % self._every == 0 or done == self.total:
            left = self.eta(now, done)
            eta = f"ETA {left:.0f}s" if left is not None else "ETA after the next generation"
            print(f"[{self.label}] gen {done}/{self.total} {info}  {self._before + now - self._t0:.0f}s, {eta}",
                  file=self._stream or sys.stderr, flush=True)
        if self._first is None:
            self._first = (now, done, self._steps)
            self._first_wall = _number(row.get("wall_time_s"))

    def count_labels(self, rows: list[dict]) -> None:
        """Count the candidates of rows shown before this display started (a resumed run)."""
        for row in rows:
            if "candidate_accepted" in row:
                self._labels(row)

    def _labels(self, row: dict, short: bool = False) -> str:
        """`` labels A/J`` (candidates accepted of judged, this display's rows) for candidate runs, with
        ``[backed off]`` while shaping sleeps (guides/label_budget.py); empty otherwise."""
        if "candidate_accepted" not in row:
            return ""
        acc = _number(row.get("candidate_accepted"))
        if acc is not None:
            self._judged, self._accepted = self._judged + 1, self._accepted + int(acc)
        asleep = _number(row.get("shaping_awake")) == 0
        if short:  # the compact line's `` 3/9 acc off``
            return f" {self._accepted}/{self._judged} acc" + (" off" if asleep else "")
        return f"  labels {self._accepted}/{self._judged}" + (" [backed off]" if asleep else "")

    def close(self) -> None:
        if self._bar is not None:
            self._bar.stop()


class RunElapsedColumn(TimeElapsedColumn):
    """rich's elapsed time plus the task's ``before`` field (what the run had taken before the bar)."""

    def render(self, task: Task) -> Text:
        elapsed = task.finished_time if task.finished else task.elapsed
        if elapsed is None:
            return Text("-:--:--", style="progress.elapsed")
        seconds = elapsed + float(task.fields.get("before", 0.0))
        return Text(str(timedelta(seconds=max(0, int(seconds)))), style="progress.elapsed")


def _number(v) -> float | None:
    """A row's value as a float (None for a missing, empty or non-numeric one)."""
    try:
        return None if v in (None, "") else float(v)
    except (TypeError, ValueError):
        return None


def _si(x: float) -> str:
    """1234 -> '1.2k', 2.5e6 -> '2.5M' (compact figures for narrow terminals)."""
    for scale, suffix in ((1e9, "G"), (1e6, "M"), (1e3, "k")):
        if abs(x) >= scale:
            return f"{x / scale:.1f}{suffix}"
    return f"{x:.0f}"
