"""envs/mujoco_batch.py: the batched MuJoCo bodies make and step with only the core dependencies (Gymnasium's
``envs.mujoco`` package imports ``imageio``, which the README's install does not bring)."""

import subprocess
import sys

import pytest

from helpers import SRC

BLOCK_IMAGEIO = '''
import sys
class Block:
    def find_spec(self, name, path=None, target=None):
        if name == "imageio" or name.startswith("imageio."):
            raise ImportError("imageio is not installed (blocked by the test)")
sys.meta_path.insert(0, Block())
import gymnasium as gym
import shaped_es.envs
for env_id in ("ReacherWay-v0", "SwimmerWay-v0"):
    env = gym.make(env_id)
    env.reset(seed=0)
    env.step(env.action_space.sample())
print("ok")
'''


def test_reacher_and_swimmer_need_no_imageio():
    pytest.importorskip("mujoco")
    res = subprocess.run([sys.executable, "-c", BLOCK_IMAGEIO], env={"PYTHONPATH": str(SRC), "PATH": ""},
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 0 and res.stdout.strip() == "ok", res.stderr[-2000:]
