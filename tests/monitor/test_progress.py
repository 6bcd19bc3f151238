"""The progress display: off a terminal the first line comes with the first generation and the ETA is
measured from it (start-up excluded); in 80 columns the terminal bar keeps steps/s and the ETA."""

import io
import re

import pytest

from rich.console import Console

from shaped_es.monitor.progress import ProgressDisplay


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


@pytest.mark.parametrize("shaped", [False, True])
def test_80_columns_keep_steps_per_second_and_the_eta(shaped):
    """A shaped run's line (its labels count, asleep) at the widest figures still fits: a new user's
    80-column terminal cut the elapsed time and the ETA off."""
    clock, file = Clock(), io.StringIO()
    console = Console(file=file, width=80, force_terminal=True, color_system=None)
    bar = ProgressDisplay(800, enabled=True, clock=clock, console=console, label="train")
    big = {"train_reward_mean": -123.45, "test_reward_mean": -123.456, "gen_env_steps": 12_345_678}
    for g in range(3):
        clock.t += 4000.0
        extra = {"candidate_accepted": str(g % 2), "shaping_awake": "0" if g == 2 else "1"} if shaped else {}
        bar.update(g, {**_row(g), **big, **extra})
    for g in range(3, 300):  # 3-digit label counts
        bar._labels({"candidate_accepted": "1", "shaping_awake": "1"})
    clock.t += 4000.0
    bar.update(300, {**_row(300), **big, **({"candidate_accepted": "1", "shaping_awake": "0"} if shaped else {})})
    bar.close()
    last = [x for x in file.getvalue().replace("\r", "\n").splitlines() if "gen 301/800" in x][-1]
    text = re.sub(r"\x1b\[[0-9;?]*[a-zA-Z]", "", last).rstrip()
    assert len(text) <= 80 and "/s" in text and "ETA" in text and "test -123.5" in text, text
    assert re.search(r"\d:\d\d:\d\d ETA [-\d]:[-\d]{2}:[-\d]{2}$", text) and "…" not in text, text  # nothing cut
    if shaped:
        assert re.search(r" \d{3}/\d{3} acc off ", text), text


def test_rows_written_together_keep_their_own_pace():
    """A generation's row waits for its test episodes, so a run's last two rows reach the display at
    once: steps/s comes from the rows' own clock (wall_time_s), not from the milliseconds between the
    two writes (a 2-generation CarNav run's last line said 2,359,153 steps/s)."""
    clock, out = Clock(), io.StringIO()
    bar = ProgressDisplay(2, enabled=True, clock=clock, stream=out, console=None)
    clock.t = 5.0  # start-up, generation 0, then generation 1 and its test episodes: rows 0 and 1 together
    bar.update(0, {**_row(0), "wall_time_s": 1.25, "gen_time_s": 1.25, "gen_env_steps": 1000})
    clock.t += 0.001
    bar.update(1, {**_row(1), "wall_time_s": 1.75, "gen_time_s": 0.5, "gen_env_steps": 1000})
    first, last = out.getvalue().splitlines()
    assert " 800 steps/s" in first  # generation 0's own: 1000 steps in 1.25 s (its start-up included)
    assert " 2,000 steps/s" in last  # 1000 steps in generation 1's 0.5 s, not 1000 / 0.001 s
    assert last.endswith("ETA 0s")


def test_steps_per_second_follow_the_rows_clock_over_the_run():
    clock, out = Clock(), io.StringIO()
    bar = ProgressDisplay(10, enabled=True, clock=clock, stream=out, console=None)
    wall = 0.0
    for g in range(10):  # each generation 4 s of the run's clock; the display sees them at odd times
        wall += 4.0
        clock.t += 0.01 if g % 2 else 7.0
        bar.update(g, {**_row(g), "wall_time_s": wall, "gen_time_s": 4.0, "gen_env_steps": 2000})
    rates = [int(re.search(r"([\d,]+) steps/s", x).group(1).replace(",", "")) for x in out.getvalue().splitlines()]
    assert rates and set(rates) == {500}


def test_a_resumed_display_counts_the_candidates_before_it():
    import io

    from shaped_es.monitor.progress import ProgressDisplay

    out = io.StringIO()
    bar = ProgressDisplay(4, 2, enabled=True, stream=out, console=None)
    bar.count_labels([{"candidate_accepted": "1"}, {"candidate_accepted": "0"}])
    bar.update(2, {"train_reward_mean": 1.0, "train_reward_max": 2.0, "candidate_accepted": "1",
                   "shaping_awake": "1"})
    assert "labels 2/3" in out.getvalue()


def test_the_elapsed_time_is_the_runs():
    """The elapsed time counts what the run took before the display started (its start-up, the shaped
    method's label probe, a resumed run's saved wall time): the plain line's and the bar's."""
    clock, out = Clock(), io.StringIO()
    bar = ProgressDisplay(4, enabled=True, clock=clock, stream=out, console=None, elapsed=30.0)
    clock.t = 2.0
    bar.update(0, _row(0))
    assert " 32s, ETA" in out.getvalue()

    clock, file = Clock(), io.StringIO()
    console = Console(file=file, width=120, force_terminal=True, color_system=None)
    bar = ProgressDisplay(4, enabled=True, clock=clock, console=console, elapsed=3725.0)
    clock.t = 5.0
    bar.update(0, _row(0))
    bar.close()
    assert "1:02:10" in file.getvalue()  # 3725 s before it + 5 s of its own
