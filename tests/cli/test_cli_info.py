"""``shaped-es config``, ``envs`` and ``check-env``: the commands that explain rather than run."""

import json
import os
import re
import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest
import yaml

from helpers import POINT_ENV_MODULE, SRC
from shaped_es.cli.commands import main
from shaped_es.config import RunConfig


def _out(capsys, argv, code=0):
    assert main(argv) == code
    return capsys.readouterr()


def test_config_prints_every_field_as_a_loadable_config(capsys):
    text = _out(capsys, ["config"]).out
    assert yaml.safe_load(text) == RunConfig().model_dump(mode="json")  # a valid --config file
    assert max(len(line) for line in text.splitlines()) <= 100
    assert "sigma: 0.05  # number > 0, <= 10000. search std" in text
    assert "optimizer: \"adam\"  # one of adam|sgd." in text
    # every leaf field of the config is there, with its description
    fields = [json.loads(line) for line in _out(capsys, ["config", "--json"]).out.splitlines()]
    keys = {f["key"] for f in fields}
    assert {"es.sigma", "shaping.cloning.steps", "ppo.n_steps", "stop_at", "wandb.mode"} <= keys
    assert all(f["description"] for f in fields)


def test_config_shows_values_and_their_defaults(capsys, tmp_path):
    (tmp_path / "c.yaml").write_text("es:\n  pairs: 8\n")
    text = _out(capsys, ["config", "es", "--config", str(tmp_path / "c.yaml"), "--set", "es.sigma=0.1"]).out
    text = re.sub(r"\n *# ", " ", text)  # comments that wrapped onto the next line: one line each
    assert "pairs: 8  # int > 0." in text and "(default: 32)" in text
    assert "sigma: 0.1  #" in text and "(default: 0.05)" in text and "\nshaping:" not in text
    assert yaml.safe_load(text)["es"]["lr"] == 0.03
    sub = _out(capsys, ["config", "shaping.cloning"]).out
    assert yaml.safe_load(sub) == {"shaping": {"cloning": RunConfig().shaping.cloning.model_dump(mode="json")}}
    err = _out(capsys, ["config", "colour"], code=2).err.strip().splitlines()
    assert len(err) == 1 and "no config field starts with 'colour'" in err[0]
    with pytest.raises(SystemExit) as exc:  # the argument parser's error: one line too
        main(["config", "--set", "es.sigma", "0.1"])
    err = capsys.readouterr().err.strip().splitlines()
    assert exc.value.code == 2 and len(err) == 1 and err[0].startswith("shaped-es: error: argument --set: "
                                                                      "expects KEY=VALUE")


def test_envs_lists_ids_presets_and_the_waypoint_contract(capsys):
    text = _out(capsys, ["envs"]).out
    lines = {line.split()[0]: line for line in text.splitlines() if line and not line[0].isspace()}
    assert "default, paper" in lines["CarNav-v0"] and "yes (2-d)" in lines["CarNav-v0"]
    assert "yes (3-d)" in lines["UR5Reach-v0"] and lines["CartPole-v1"].rstrip().endswith("no")
    assert "cannot be used here:" not in text and "--all" in text  # the ids that cannot be used: only with --all
    assert "(act: the policy's outputs: the action size of a Box, the options of a Discrete" in text
    assert lines["Blackjack-v1"].split()[2] == "45"  # a Tuple of Discretes, flattened one-hot (32 + 11 + 2)
    rows = [json.loads(x) for x in _out(capsys, ["envs", "--all", "--json"]).out.splitlines()]
    by = {r["id"]: r for r in rows}
    assert any(r["error"] for r in rows) and by["CarNav-v0"]["waypoints"] == 2  # the Mujoco-v2 ids, at least


INFOPOINT = POINT_ENV_MODULE + '''

class InfoPoint(Point):
    """Point with the waypoint contract: its position, and the origin as the waypoint."""

    def _info(self):
        return {"position": self.x.copy(), "waypoint": np.zeros(2, np.float32)}

    def reset(self, *, seed=None, options=None):
        return super().reset(seed=seed)[0], self._info()

    def step(self, action):
        return (*super().step(action)[:4], self._info())


gym.register("InfoPoint-v0", entry_point=InfoPoint, max_episode_steps=20)
gym.register("InfoPointNaN-v0", entry_point=lambda: gym.wrappers.TransformReward(InfoPoint(), lambda r: float("nan")),
             max_episode_steps=20)
'''


def _cli(tmp_path, *argv):
    (tmp_path / "infopoint.py").write_text(INFOPOINT)
    env = {**os.environ, "PYTHONPATH": str(SRC)}  # this tree's package; the env's module from the cwd
    return subprocess.run([sys.executable, "-m", "shaped_es", *argv], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300, env=env)


def test_envs_and_check_env_on_an_own_env(tmp_path):
    res = _cli(tmp_path, "envs", "--import", "infopoint")
    assert res.returncode == 0, res.stderr
    assert any(line.startswith("InfoPoint-v0") and "yes (2-d)" in line for line in res.stdout.splitlines())
    res = _cli(tmp_path, "check-env", "infopoint:InfoPoint-v0")
    assert res.returncode == 0, res.stderr
    lines = res.stdout.strip().splitlines()
    # no threshold registered, no controller (both optional)
    assert [line.split()[0] for line in lines[:-1]] == ["ok"] * 3 + ["no"] + ["ok"] * 4 + ["no"]
    assert lines[-1] == "infopoint:InfoPoint-v0 trains with: vanilla, guided, cmaes, shaped, shaped_cmaes, ppo"
    res = _cli(tmp_path, "check-env", "infopoint:InfoPointNaN-v0", "--json")
    assert res.returncode == 1  # a FAIL: exit code 1
    out = json.loads(res.stdout)
    assert out["trains_with"] == [] and any(c["status"] == "FAIL" and c["name"] == "steps" for c in out["checks"])
    res = _cli(tmp_path, "check-env", "infopoint:InfoPointNaN-v0", "--labels")  # not "no waypoint contract"
    assert res.returncode == 1 and res.stdout.strip().splitlines()[-1] == (
        "labels: not probed: the env cannot train here (the FAIL line above)")
    res = _cli(tmp_path, "check-env", "NoSuchEnv-v0")
    assert res.returncode == 2 and res.stderr.startswith("shaped-es: error: cannot make env")


def test_list_fields_name_their_item_type(capsys):
    """``shaping.mean_clone.scales`` holds positive numbers (scales), ``policy.hidden`` integer widths."""
    fields = {f["key"]: f for f in map(json.loads, _out(capsys, ["config", "--json"]).out.splitlines())}
    assert fields["shaping.mean_clone.scales"]["type"] == "list of numbers"
    assert "positive number" in fields["shaping.mean_clone.scales"]["description"]
    assert fields["policy.hidden"]["type"] == "list of ints"


def test_check_env_labels_drives_the_body_with_m_phi_labels(capsys):
    """``--labels``: the label probe of a shaped run with frame auto, against zero action, with its choice."""
    lines = _out(capsys, ["check-env", "PointVel-v0", "--labels"]).out.strip().splitlines()
    assert lines[-8].startswith("labels: label-driven return over 10 episodes: both ")
    assert "zero action -1.00" in lines[-8]
    assert lines[-7].startswith("labels: the simulated candidate's return (the initial mean cloned toward ")
    # the probe of seed 0, not every run's pick: each run probes with its own seed (9 of 10 may pick another)
    assert lines[-6].startswith("labels: with seed 0 a shaped run picks frame=")
    assert lines[-6].endswith("; each run probes with its own seed")
    assert lines[-5].startswith("labels: both's simulated candidate (what the frame was chosen on) scores ")
    assert lines[-4].startswith("labels: the shooting labels' simulated candidate (actions held ")
    assert "a run keeps that rival" in lines[-4]
    assert lines[-3].startswith("labels: M_phi does not see each step's change from the last")  # a first-order point
    # the best simulated candidate, judged beside generation 0 (guides/probe_candidate.py)
    assert lines[-2].startswith("labels: a run judges the best simulated candidate beside generation 1, as its ")
    assert lines[-1].startswith("labels: both's labels drive the body: they beat zero action")  # they pay
    assert max(len(ln) for ln in lines[-5:]) < 300  # one fact a line
    out = json.loads(_out(capsys, ["check-env", "PointVel-v0", "--labels", "--json"]).out)
    assert set(out["labels"]["returns"]) == {f"{f}{k}{c}" for f in ("both", "world") for k in ("", "+chunk4")
                                             for c in ("", "+clip2", "+clip4")}  # one-step and chunk targets, 3 clips
    assert "chunk" in out["labels"]["chosen"]
    assert set(out["labels"]["clones"]) == set(out["labels"]["returns"])
    assert len(out["labels"]["zero_action"]) == 10 and out["labels"]["env_steps"] > 0 and out["labels"]["seed"] == 0
    assert len(out["labels"]["shoot"]) == 10 and out["labels"]["shoot_on"] is True  # the point: kept
    # every probed horizon's candidate, and the chosen one's returns are its
    tried = out["labels"]["shoot_tried"]
    assert set(tried) == {"4", "8", "16", "32"} and tried[str(out["labels"]["shoot_horizon"])] == out["labels"]["shoot"]
    text = _out(capsys, ["check-env", "CartPole-v1", "--labels"]).out
    assert text.strip().splitlines()[-1].startswith("labels: no waypoint contract")
    out = json.loads(_out(capsys, ["check-env", "CartPole-v1", "--labels", "--json"]).out)
    assert out["labels"]["verdict"].startswith("no waypoint contract")


class _GridMoves(gym.Env):
    """Five moves of 0.1 (0 stays) towards a goal, the two-key contract: a Discrete body."""

    observation_space = gym.spaces.Box(-3, 3, (4,), np.float32)
    action_space = gym.spaces.Discrete(5)
    MOVES = np.array([[0, 0], [0, 1], [0, -1], [-1, 0], [1, 0]], np.float32) * 0.1

    def _out(self):
        d = self.goal - self.pos
        info = {"position": self.pos.copy(), "waypoint": self.pos + d * min(1.0, 0.1 / max(np.linalg.norm(d), 1e-6))}
        return np.concatenate([self.pos, self.goal]).astype(np.float32), info

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.pos, self.goal = np.zeros(2, np.float32), self.np_random.uniform(-1, 1, 2).astype(np.float32)
        return self._out()

    def step(self, action):
        before = np.linalg.norm(self.goal - self.pos)
        self.pos = self.pos + self.MOVES[int(action)]
        return (*self._out()[:1], float(before - np.linalg.norm(self.goal - self.pos)), False, False,
                self._out()[1])


gym.register("CheckGridMoves-v0", entry_point=_GridMoves, max_episode_steps=30)


def test_check_env_labels_says_what_zero_action_is_on_a_discrete_body(capsys):
    """A new user's grid, whose action 0 moved: "beats zero action" read as a verdict; zero action is action 0."""
    out = _out(capsys, ["check-env", "CheckGridMoves-v0", "--labels"]).out
    assert "labels: zero action is action 0 here (a space of choices: a zero output's argmax is action 0 of each " \
           "choice" in out and "make action 0 the no-op" in out
