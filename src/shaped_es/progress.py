"""Live progress for long runs: a rich bar on a terminal, a plain line every few generations otherwise."""

from __future__ import annotations

import sys
import time

from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn


class ProgressDisplay:
    def __init__(self, total: int, start: int = 0, enabled: bool = True, label: str = "train"):
        self.total, self.enabled, self.label = total, enabled, label
        self._t0, self._start = time.perf_counter(), start
        self._steps = 0
        self._live = enabled and sys.stderr.isatty()
        self._every = max(1, (total - start) // 20)
        self._bar = None
        self._compact = False
        if self._live:
            console = Console(stderr=True)
            # below ~110 columns the bar graphic and the least needed figures go first, so that the
            # generation count and the ETA always fit (rich cuts a line's end otherwise)
            self._compact = console.width < 110
            bar = [] if self._compact else [BarColumn(bar_width=24)]
            self._bar = Progress(
                TextColumn("[bold]{task.description}"),
                *bar,
                TextColumn("gen {task.completed}/{task.total}"),
                TextColumn("{task.fields[info]}"),
                TimeElapsedColumn(),
                TextColumn("ETA"),
                TimeRemainingColumn(),
                console=console,
                transient=False,
            )
            self._bar.start()
            self._task = self._bar.add_task(label, total=total, completed=start, info="")

    def update(self, generation: int, row: dict) -> None:
        if not self.enabled:
            return
        self._steps += int(row.get("gen_env_steps", 0) or 0)
        rate = self._steps / max(time.perf_counter() - self._t0, 1e-9)
        test = row.get("test_reward_mean")
        test_s = "" if test in (None, "") else f" test {float(test):8.2f}"
        if self._compact:
            info = f"train {row['train_reward_mean']:7.1f}{'' if not test_s else f' test {float(test):7.1f}'}"
        else:
            info = (f"train mean {row['train_reward_mean']:8.2f} max {row['train_reward_max']:8.2f}"
                    f"{test_s}  {rate:,.0f} steps/s")
        done = generation + 1
        if self._bar is not None:
            self._bar.update(self._task, completed=done, info=info)
        elif done % self._every == 0 or done == self.total:
            elapsed = time.perf_counter() - self._t0
            left = elapsed / max(done - self._start, 1) * (self.total - done)  # at the pace so far
            print(f"[{self.label}] gen {done}/{self.total} {info}  {elapsed:.0f}s, ETA {left:.0f}s",
                  file=sys.stderr, flush=True)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.stop()
