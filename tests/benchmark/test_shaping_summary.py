"""What shaping did, per method, in a benchmark's summary and report (benchmark/shaping_summary.py): counts
by label variant, runs where nothing was accepted (and the line saying so), none for methods without
candidates."""

import numpy as np

from shaped_es.benchmark.shaping_summary import shaping_lines, shaping_summary

nan = np.nan


def _run(acc, rival, gain, awake):
    return {"candidate_accepted": np.array(acc, float), "candidate_rival": np.array(rival, float),
            "candidate_gain": np.array(gain, float), "shaping_awake": np.array(awake, float)}


def test_counts_by_variant_backoff_and_runs_without_acceptance():
    runs = [_run([nan, 1, 0, 1, 1, 1, 1, 1], [nan, 2, 0, 0, 1, 3, 4, 8], [nan, 2.0, -1.0, 1.0, 3.0, 0.0, 1.0, 0.5],
                 [1] * 8),
            _run([nan, 0, 0, nan, nan], [nan, 1, 2, nan, nan], [nan, -4.0, -2.0, nan, nan], [1, 1, 1, 0, 0])]
    s = shaping_summary(runs)
    assert (s["candidates_judged"], s["candidates_accepted"]) == (9, 6)
    assert s["accepted_by_variant"] == {"own": 1, "rival_frame": 1, "servo": 1, "shoot": 1, "shoot_base": 1,
                                        "probe": 0, "shoot_hold": 1}
    assert s["mean_gain"] == np.mean([2.0, -1.0, 1.0, 3.0, 0.0, 1.0, 0.5, -4.0, -2.0])
    assert s["generations_backed_off_mean"] == 1.0 and s["runs_without_acceptance"] == 1
    assert shaping_summary([{"test_reward_mean": np.zeros(3)}]) is None  # vanilla: no candidates


def test_the_report_says_when_no_candidate_was_ever_accepted():
    lost = _run([nan, 0, 0, 0], [nan, 0, 2, 1], [nan, -1.0, -2.0, -3.0], [1, 1, 1, 0])
    methods = {"shaped": {"shaping": shaping_summary([lost, lost]), "wall_time_s": 15.0},
               "vanilla": {"wall_time_s": 10.0}}
    text = "\n".join(shaping_lines(methods, {k: v["wall_time_s"] for k, v in methods.items()}))
    assert "| shaped | 6 | 0 (0 / 0 / \u2013 / \u2013 / \u2013 / \u2013 / \u2013) |" in text and "2/2 |" in text  # no rival ran
    assert "no candidate was accepted in any run" in text and "1.50x vanilla's wall time" in text
    assert shaping_lines({"vanilla": {"wall_time_s": 1.0}}) == []


def test_a_rival_dropped_in_some_runs_is_told_apart_from_one_that_never_won():
    """The shooting rival ran (its gain column filled) in one of two runs, the servo in both, the frame in none."""
    a = _run([nan, 1, 0], [nan, 2, 3], [nan, 1.0, -1.0], [1, 1, 1]) | {"servo_gain": np.array([nan, 1.0, -2.0]),
                                                                     "shoot_gain": np.array([nan, -1.0, 0.5])}
    b = _run([nan, 0, 0], [nan, 2, 0], [nan, -1.0, -1.0], [1, 1, 1]) | {"servo_gain": np.array([nan, -1.0, -2.0])}
    s = shaping_summary([a, b])
    assert s["runs_with_rival"] == {"rival_frame": 0, "servo": 2, "shoot": 1, "shoot_base": 0, "shoot_hold": 0}
    text = "\n".join(shaping_lines({"shaped": {"shaping": s}}))
    assert "| shaped | 4 | 1 (0 / 0 / \u2013 / 1 / 0 (ran in 1/2 runs) / \u2013 / \u2013) |" in text


def test_generation_0s_probe_candidate_is_counted_apart_from_the_labels():
    """A new user's 3-link arm: 8 generation-0 wins of the probe's candidate (the shooting labels' clone) were
    counted as the run's own labels'. Now 5 (mechanisms/candidate.PROBE) marks them; a run from before the value
    (blank at generation 0) is read the same."""
    runs = [_run([1, 1, 0], [5, 0, 3], [1.0, 1.0, -1.0], [1, 1, 1]), _run([1, 0, 1], [nan, 3, 3], [2.0, -1.0, 1.0],
                                                                          [1, 1, 1])]
    s = shaping_summary(runs)
    assert s["accepted_by_variant"] == {"own": 1, "rival_frame": 0, "servo": 0, "shoot": 1, "shoot_base": 0,
                                        "probe": 2, "shoot_hold": 0}
    assert "| shaped | 6 | 4 (2 / 1 / " in "\n".join(shaping_lines({"shaped": {"shaping": s}}))


def test_the_report_counts_what_each_runs_label_probe_chose(tmp_path):
    """Runs per frame and per shooting horizon, read from each run's label_probe.json (a run without one, or
    with a damaged one, is left out; none readable: None)."""
    import json

    from shaped_es.benchmark.shaping_summary import probe_choices

    base = {"query_clip": None, "returns": {}, "env_steps": 10, "seconds": 1.0, "reason": "r"}
    probes = [{"frame": "world", "shoot_on": True, "shoot_horizon": 16}, {"frame": "world", "shoot_on": False},
              {"frame": "both", "shoot_on": True, "shoot_horizon": 4}, {"frame": "both"},
              {"frame": "both", "chunk": 4, "shoot_on": True, "shoot_horizon": 4},
              {"frame": "world", "query_clip": 4.0, "shoot_on": True, "shoot_horizon": 4}]
    dirs = []
    for i, p in enumerate(probes + ["not json", None]):
        d = tmp_path / f"run{i}"
        d.mkdir()
        if p is not None:
            (d / "label_probe.json").write_text(json.dumps(base | p) if isinstance(p, dict) else p)
        dirs.append(d)
    got = probe_choices(dirs)
    assert got == {"frame": {"world": 2, "both": 2, "both with chunk targets": 1, "world, query clip 4": 1},
                   "shoot": {"16 steps": 1, "dropped": 1, "4 steps": 3, "config": 1}}
    assert probe_choices(dirs[6:]) is None
    got = probe_choices(dirs[:5])
    s = shaping_summary([_run([nan, 1], [nan, 0], [nan, 1.0], [1, 1])]) | {"label_probe": got}
    text = "\n".join(shaping_lines({"shaped": {"shaping": s}}))
    assert "shaped's label probe, runs per choice: frame world (2); both (2); both with chunk targets (1); the " \
           "shooting rival 4 steps (2); 16 steps (1); config (1); dropped (1)" in text


def test_jumps_undone_a_generation_later_are_counted_and_said():
    """revert_paired: the rows after jumps say whether each was undone (``jump_reverted``); the summary pools them
    and the report says how many of the accepted; runs without the column (older runs, the option off) say nothing."""
    a = _run([nan, 1, 0, 1, 0], [nan, 0, 0, 3, 0], [nan, 1.0, -1.0, 2.0, 0.5], [1] * 5) | {
        "jump_reverted": np.array([0, 0, 1, 0, 0], float)}
    b = _run([nan, 1, 1], [nan, 2, 0], [nan, 1.0, 1.0], [1, 1, 1]) | {"jump_reverted": np.array([0, 0, 1], float)}
    s = shaping_summary([a, b])
    assert s["jumps_reverted"] == 2 and s["candidates_accepted"] == 4
    assert "shaped 2 of its 4." in "\n".join(shaping_lines({"shaped": {"shaping": s}}))
    old = shaping_summary([_run([nan, 1], [nan, 0], [nan, 1.0], [1, 1])])
    assert old["jumps_reverted"] is None and "undone" not in "\n".join(shaping_lines({"shaped": {"shaping": old}}))
