"""A user's env edited after its runs were made (rundir/env_source.py): the run's ``run.json`` keeps the env module's
source hash; a benchmark rerun that reuses such runs, and a resume of one, say so in one warning line (a new user
edited the env and expected the rerun to redo the runs). Built-in envs keep none."""

import json
import sys

import pytest

from shaped_es.cli.commands import main
from shaped_es.rundir.env_source import changed, fingerprint
from shaped_es.rundir.store import RunStore

ENV = '''import gymnasium as gym
import numpy as np


class Line(gym.Env):
    observation_space = gym.spaces.Box(-5.0, 5.0, (1,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (1,), np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.x, self.t = 0.0, 0
        return np.array([self.x], np.float32), {}

    def step(self, action):
        self.x += 0.1 * float(action[0])
        self.t += 1
        return np.array([self.x], np.float32), -abs(1.0 - self.x), False, self.t >= 10, {}


gym.register("EditedLine-v0", entry_point=Line, max_episode_steps=10)
'''


@pytest.fixture
def user_env(tmp_path, monkeypatch):
    (tmp_path / "edited_line.py").write_text(ENV)
    monkeypatch.chdir(tmp_path)
    monkeypatch.syspath_prepend(str(tmp_path))
    yield tmp_path / "edited_line.py"
    sys.modules.pop("edited_line", None)


def test_the_fingerprint_is_the_named_modules_source_and_none_for_built_ins(user_env):
    fp = fingerprint("edited_line:EditedLine-v0")
    assert fp["module"] == "edited_line" and fp["file"] == str(user_env.resolve()) and len(fp["sha256"]) == 64
    assert fingerprint("CartPole-v1") is None and fingerprint("shaped_es:UR5Reach-v0") is None
    assert fingerprint("no_such_module_here:X-v0") is None
    assert changed(fp, fingerprint("edited_line:EditedLine-v0")) is None
    user_env.write_text(ENV + "# tuned\n")
    assert changed(fp, fingerprint("edited_line:EditedLine-v0")) == "edited_line.py"
    assert changed(None, fingerprint("edited_line:EditedLine-v0")) is None  # a run made before fingerprints: nothing said


def _bench(out, gens=2):
    return main(["benchmark", "--env", "edited_line:EditedLine-v0", "--methods", "vanilla", "--seeds", "1",
                 "--generations", str(gens), "--executor", "inline", "--no-estimate", "--quiet",
                 "--set", "tensorboard=false", "--set", "es.pairs=2", "--out", str(out)])


def test_a_rerun_and_a_resume_on_an_edited_env_say_so(user_env, capsys):
    out = user_env.parent / "bench"
    assert _bench(out) == 0
    run = out / "runs" / "vanilla_s0"
    assert json.loads((run / "run.json").read_text())["env_source"]["module"] == "edited_line"
    capsys.readouterr()
    assert _bench(out) == 0  # the same env: nothing said
    assert "changed since" not in capsys.readouterr().err
    user_env.write_text(ENV.replace("0.1 * float", "0.2 * float"))
    assert _bench(out) == 0
    err = capsys.readouterr().err
    assert ("shaped-es: warning: edited_line.py changed since runs vanilla_s0 in " in err
            and "they are reused as they are" in err)
    assert main(["resume", str(run), "--generations", "3", "--quiet"]) == 0
    assert f"edited_line.py changed since {run} was made: the run continues on the env as it is now" in \
        capsys.readouterr().err
    assert RunStore(run).env_changed("edited_line:EditedLine-v0") == "edited_line.py"
