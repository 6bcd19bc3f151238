"""The progress display: off a terminal the first line comes with the first generation and the ETA is
measured from it (start-up excluded); in 80 columns the terminal bar keeps steps/s and the ETA."""

import io
import re

from rich.console import Console

from shaped_es.progress import ProgressDisplay


class Clock:
    def __init__(self):
        self.t = 0.0

    def __call__(self):
        return self.t


def _row(g):
    return {"generation": g, "train_reward_mean": -1.5, "train_reward_max": 2.0, "test_reward_mean": 3.25,
            "gen_env_steps": 1000}


def test_plain_lines_come_at_once_and_the_eta_leaves_the_start_up_out():
    clock, out = Clock(), io.StringIO()
    bar = ProgressDisplay(60, enabled=True, clock=clock, stream=out, console=None)
    assert bar._bar is None  # pytest's stderr is no terminal
    clock.t = 20.0  # start-up (workers, compiled kernels) + the first generation
    bar.update(0, _row(0))
    lines = out.getvalue().splitlines()
    assert len(lines) == 1 and lines[0].startswith("[train] gen 1/60") and "ETA after the next" in lines[0]
    for g in range(1, 60):  # then 2 s a generation
        clock.t += 2.0
        bar.update(g, _row(g))
    lines = out.getvalue().splitlines()
    assert lines[1].startswith("[train] gen 2/60") and lines[1].endswith("ETA 116s")  # 58 left x 2 s
    assert "500 steps/s" in lines[1]  # 1000 steps per 2 s since the first line
    assert [int(re.search(r"gen (\d+)/", x).group(1)) for x in lines] == [1, 2, 3, *range(6, 61, 3)]
    assert lines[-1].endswith("ETA 0s")


def test_80_columns_keep_steps_per_second_and_the_eta():
    clock, file = Clock(), io.StringIO()
    console = Console(file=file, width=80, force_terminal=True, color_system=None)
    bar = ProgressDisplay(60, enabled=True, clock=clock, console=console, label="train")
    for g in range(3):
        clock.t += 1.0
        bar.update(g, {**_row(g), "gen_env_steps": 1_234_567})
    bar.close()
    last = [x for x in file.getvalue().replace("\r", "\n").splitlines() if "gen 3/60" in x][-1]
    text = re.sub(r"\x1b\[[0-9;?]*[a-zA-Z]", "", last).rstrip()
    assert len(text) <= 80 and "steps/s" in text and "ETA" in text and "test 3.2" in text, text
