"""The benchmark's verdict lines (benchmark/verdict.py): each method against Vanilla-ES, from the summary."""

from shaped_es.benchmark.verdict import verdict_lines


def _method(successes, wall, late, shaping=None):
    return {"seeds": 5, "successes": successes, "wall_time_s": wall, "late_test_reward_iqm": late,
            **({"shaping": shaping} if shaping else {})}


def _summary(shaped, vanilla, ratios=None):
    return {"threshold": {"value": 9.0}, "methods": {"shaped": shaped, "vanilla": vanilla},
            "ratios_to_threshold": {"shaped": {"vanilla": ratios or {}}}}


def test_a_run_that_gained_nothing_says_so_and_its_price():
    """A new user's quadrotor: no seed of either reached the threshold, shaped cost 2.65x the wall time; the
    terminal said only where report.md was."""
    sh = {"candidates_judged": 231, "candidates_accepted": 41, "runs_without_acceptance": 1, "runs": 5}
    lines = verdict_lines(_summary(_method(0, 26.5, 1.61, sh), _method(0, 10.0, 1.84)))
    assert lines == ["shaped vs vanilla: late test reward IQM 1.61 vs 1.84; 0/5 vs 0/5 seeds reached 9; neither "
                     "reached it; whole runs' wall time 2.65x; candidates accepted 41 of 231 (1 of 5 runs none: "
                     "vanilla's own steps there)"]


def test_few_runs_reaching_the_threshold_lead_with_the_late_reward():
    """Two new users' bodies (an attitude controller, a forklift): 1/10 and 0/10 reached check-env's bar; the line
    led with "wall time to it 2.19x", whole runs' lengths, where shaped ended at three times Vanilla-ES's reward."""
    ratios = {"generations": {"ratio": 0.98, "ci": [0.93, 1.0]}, "wall_time_s": {"ratio": 2.19, "ci": [2.0, 2.4]}}
    (line,) = verdict_lines(_summary(_method(2, 21.9, 15.94), _method(0, 10.0, 4.79), ratios), "bench")
    assert line == ("shaped vs vanilla: late test reward IQM 15.94 vs 4.79; 2/5 vs 0/5 seeds reached 9; too few runs "
                    "reached it for ratios to it to tell (shaped-es report bench --threshold T --out "
                    "report_T/report.md compares them at a bar T below 9); whole runs' wall time 2.19x")
    (line,) = verdict_lines(_summary(_method(0, 21.9, 1.2), _method(0, 10.0, -0.8)), "bench")
    assert line.startswith("shaped vs vanilla: late test reward IQM 1.20 vs -0.80; 0/5 vs 0/5 seeds reached 9; "
                           "neither reached it (shaped-es report bench")
    # half of one side reached it: the ratios, as before
    (line,) = verdict_lines(_summary(_method(3, 21.9, 15.94), _method(0, 10.0, 4.79), ratios), "bench")
    assert "generations to it 0.98x" in line and "report bench" not in line


def test_ratios_to_the_threshold_with_their_intervals():
    ratios = {"generations": {"ratio": 0.5, "ci": [0.31, 0.78]}, "wall_time_s": {"ratio": 1.73, "ci": [1.25, 2.41]}}
    (line,) = verdict_lines(_summary(_method(5, 19.4, 9.23), _method(4, 10.0, 9.41), ratios))
    assert line.startswith("shaped vs vanilla: 5/5 vs 4/5 seeds reached 9; generations to it 0.50x [0.31, 0.78]; "
                           "wall time to it 1.73x [1.25, 2.41] (vanilla's 1 unsolved run counts its whole length: "
                           "the ratios are upper bounds); whole runs' wall time 1.94x")
    # a new user's arm: Vanilla-ES reached it on no seed; and the other way round; and both short
    (line,) = verdict_lines(_summary(_method(5, 19.4, 9.23), _method(0, 10.0, 9.41), ratios))
    assert "(vanilla's 5 unsolved runs count their whole length: the ratios are upper bounds)" in line
    (line,) = verdict_lines(_summary(_method(3, 19.4, 9.23), _method(5, 10.0, 9.41), ratios))
    assert "(shaped's 2 unsolved runs count their whole length: the ratios are lower bounds)" in line
    (line,) = verdict_lines(_summary(_method(3, 19.4, 9.23), _method(4, 10.0, 9.41), ratios))
    assert "(unsolved runs on both sides count their whole length: the ratios are rough)" in line
    (line,) = verdict_lines(_summary(_method(5, 19.4, 9.23), _method(5, 10.0, 9.41), ratios))
    assert "unsolved" not in line


def test_the_first_method_is_the_baseline_without_vanilla_and_one_method_has_no_verdict():
    s = {"threshold": {"value": 1.0}, "methods": {"cmaes": _method(1, 2.0, 0.5), "shaped": _method(2, 4.0, 0.7)}}
    (line,) = verdict_lines(s)
    assert line.startswith("shaped vs cmaes: late test reward IQM 0.70 vs 0.50; 2/5 vs 1/5 seeds reached 1;")
    assert "whole runs' wall time 2.00x" in line
    assert verdict_lines({"threshold": {"value": 1.0}, "methods": {"shaped": _method(1, 2.0, 0.5)}}) == []


def test_the_suite_counts_run_lines_only():
    """A suite's progress counts runs by their lines; the verdict lines and the page's note are not runs (a
    suite of one seed a task printed "2/1 runs")."""
    from shaped_es.benchmark.suite import RUN_LINE

    assert RUN_LINE.match("[benchmark] shaped_s1: new (20.2 s), last test reward 229.06")
    assert RUN_LINE.match("[benchmark] lean[x=1]_s12: resumed (3.0 s)")
    for msg in ("[benchmark] shaped vs vanilla: 5/5 vs 4/5 seeds reached 9",
                "[benchmark] report.md shows this invocation's methods and seeds; DIR/runs also holds shaped_s1 (1)",
                "[benchmark] estimate: shaped ~1 min"):
        assert not RUN_LINE.match(msg)


def test_a_threshold_no_one_gave_is_named_as_such():
    """A new user's car without a registered threshold: the bar was Vanilla-ES's final mean, the reward for
    leaving the arena, and the verdict read "wall time to it 7.44x" where Vanilla-ES learned nothing."""
    from shaped_es.benchmark.summary import FALLBACK_SOURCE

    summary = _summary(_method(3, 19.4, 2.75), _method(3, 10.0, -4.65))
    summary["threshold"] = {"value": -4.80778, "source": FALLBACK_SOURCE}
    lines = verdict_lines(summary)
    assert len(lines) == 2 and lines[1].startswith("-4.80778 is the best baseline's final mean (the env registers "
                                                   "no reward_threshold and no --threshold was given)")
    summary["threshold"]["source"] = "given (--threshold)"
    assert len(verdict_lines(summary)) == 1
