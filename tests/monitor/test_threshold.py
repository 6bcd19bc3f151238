"""The env's threshold during a run (monitor/threshold.py): one line when the test reward first reaches
it, nothing again on a resume that had reached it, and the first generation in ``train``'s final JSON."""

import csv
import io
import json
from pathlib import Path
from types import SimpleNamespace

from shaped_es.cli.commands import main
from shaped_es.monitor.threshold import ThresholdNotice


class _Store:
    def __init__(self, root: Path, rows: list[dict]):
        self.root, self._rows = root, rows

    def read_metrics(self) -> list[dict]:
        return self._rows


def _rows(tests):
    return [{"generation": str(g), "test_reward_mean": str(t)} for g, t in enumerate(tests)]


def test_one_line_at_the_first_crossing(tmp_path):
    out = io.StringIO()
    n = ThresholdNotice(8.0, "My-v0 reward_threshold (registered with its Gymnasium spec)", stream=out)
    n.on_start(SimpleNamespace(store=_Store(tmp_path / "myrun", [])))
    for row in _rows([1.0, 7.9, 8.1, 9.0, 7.0, 8.5]):
        assert n.on_generation(row) is True
    assert out.getvalue() == ("shaped-es: myrun: test reward 8.10 reached the threshold 8 (My-v0 reward_threshold) "
                              "at generation 3\n")
    assert n.first == 3


def test_a_resume_that_had_reached_it_says_nothing(tmp_path):
    out = io.StringIO()
    n = ThresholdNotice(8.0, "x", stream=out)
    n.on_start(SimpleNamespace(store=_Store(tmp_path / "r", _rows([1.0, 8.2]))))
    n.on_generation({"generation": "2", "test_reward_mean": "9.0"})
    assert out.getvalue() == "" and n.first == 2


def test_train_json_says_the_threshold_and_when(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["train", "--env", "PointVel-v0", "--method", "vanilla", "--generations", "2", "--out", "r",
                 "--quiet", "--executor", "inline", "--pairs", "2", "--set", "rollout.episodes=1",
                 "--set", "tensorboard=false"]) == 0
    out = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert out["threshold"]["value"] == 8.5 and out["threshold"]["source"].startswith("PointVel-v0 reward_threshold")
    with open("r/metrics.csv", newline="") as fh:
        tests = [float(r["test_reward_mean"]) for r in csv.DictReader(fh)]
    first = next((i + 1 for i, t in enumerate(tests) if t >= 8.5), None)
    assert out["threshold"]["first_generation"] == first
