"""Shared helpers for the fault-injection tests: the command line as a subprocess (so that it can be
SIGKILLed for real), tiny run configs, and snapshots of a run directory. (A module of its own name, not
conftest.py: ``from conftest import`` found whichever conftest pytest had loaded last.)"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import yaml

HERE = Path(__file__).resolve().parent
SRC = HERE.parents[1] / "src"

# Tiny runs (seconds each): CartPole for the ES baselines and PPO, fault_envs:Reach-v0 for shaped.
BASE = {"env": "CartPole-v1", "executor": "inline", "generations": 6, "seed": 3, "es": {"pairs": 4},
        "policy": {"hidden": [4]}, "rollout": {"episodes": 1, "test_episodes": 2}, "tensorboard": False}
METHODS = {
    "vanilla": {"method": "vanilla"},
    "cmaes": {"method": "cmaes"},
    "shaped": {"method": "shaped", "env": "fault_envs:Reach-v0",
               "shaping": {"history": 2, "inverse_dynamics": {"steps_per_generation": 20, "min_return": -1e9},
                           "cloning": {"steps": 3}}},
    "shaped_ce3": {"method": "shaped", "env": "fault_envs:Reach-v0", "checkpoint_every": 3,
                   "shaping": {"history": 2, "inverse_dynamics": {"steps_per_generation": 20,
                                                                  "min_return": -1e9},
                               "cloning": {"steps": 3}}},
    "ppo": {"method": "ppo", "rollout": {"episodes": 1, "test_episodes": 2, "max_steps": 40},
            "ppo": {"steps_per_generation": 64, "n_steps": 32, "batch_size": 32, "n_epochs": 1}},
}


def config(name: str, **over) -> dict:
    out = {**BASE, **METHODS[name]}
    out.update(over)
    return out


def env() -> dict:
    path = [str(SRC), str(HERE)] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
    return {**os.environ, "PYTHONPATH": os.pathsep.join(path)}


def run_cli(*args, timeout: float = 300, cwd=None, prefix=None, memory_gib: float | None = None
            ) -> subprocess.CompletedProcess:
    """The command line in a process of its own (``memory_gib``: its address space is capped there, so
    that a case that would blow up fails there rather than take the machine's memory)."""
    cmd = [sys.executable, *(prefix or ["-m", "shaped_es.cli.commands"]), *map(str, args)]

    def cap() -> None:  # pragma: no cover - runs in the child
        import resource

        limit = int(memory_gib * 2**30)
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))

    return subprocess.run(cmd, env=env(), cwd=cwd or HERE, capture_output=True, text=True, timeout=timeout,
                          preexec_fn=cap if memory_gib else None)


def popen_cli(*args, prefix=None, **kw) -> subprocess.Popen:
    cmd = [sys.executable, *(prefix or ["-m", "shaped_es.cli.commands"]), *map(str, args)]
    return subprocess.Popen(cmd, env=env(), cwd=HERE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, **kw)


def write_config(path: Path, cfg: dict) -> Path:
    path.write_text(yaml.safe_dump(cfg))
    return path


def snapshot(root: Path) -> dict[str, str]:
    """sha256 of every file under ``root`` (error.log aside: it only ever grows with tracebacks)."""
    if not root.exists():
        return {}
    if root.is_file():
        return {".": hashlib.sha256(root.read_bytes()).hexdigest()}
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(root.rglob("*")) if p.is_file() and p.name != "error.log"}


def leftovers(root: Path) -> list[str]:
    """What a consistent run directory must not hold: temporaries, half checkpoints, a lock."""
    bad = [str(p.relative_to(root)) for p in root.rglob("*.tmp")]
    ck = root / "checkpoints"
    if ck.is_dir():
        names = {p.name for p in ck.iterdir()}
        bad += [n for n in names if n.startswith("gen_") and
                ({n[:-4] + ".json", n[:-5] + ".npz"} & names) == set()]
    if (root / ".lock").exists():
        bad.append(".lock")
    return bad


def one_error_line(stderr: str) -> str:
    lines = [l for l in stderr.splitlines() if l.strip() and not l.startswith("shaped-es: warning:")]
    assert len(lines) == 1 and lines[0].startswith("shaped-es: error: "), stderr[-3000:]
    return lines[0]


# -- damage to a saved run, as table entries: f(run, tmp) (run: the run directory, tmp: the test's) ------
def newest(run: Path, suffix: str) -> Path:
    """The newest checkpoint's ``.npz`` or ``.json`` of ``run``."""
    return sorted((run / "checkpoints").glob(f"gen_*{suffix}"))[-1]


def write(rel, data):
    def f(run, tmp):
        p = run / rel
        p.write_bytes(data) if isinstance(data, bytes) else p.write_text(data)
    return f


def edit_json(rel, fn):
    """``rel``: a path in the run, or None for the newest checkpoint's ``.json``."""
    def f(run, tmp):
        p = run / rel if rel else newest(run, ".json")
        p.write_text(json.dumps(fn(json.loads(p.read_text()))))
    return f


def edit_text(rel, fn):
    def f(run, tmp):
        p = run / rel
        p.write_text(fn(p.read_text()))
    return f


def edit_npz(fn, rebind: bool = True):
    """The newest checkpoint's arrays replaced by ``fn(arrays)`` (``rebind``: still bound to the run and
    generation, and the ``.json``'s digest made to match, so that what is checked is the arrays
    themselves; otherwise the edit is refused as a replaced file)."""
    def f(run, tmp):
        try:
            from shaped_es.rundir.store import BIND_PREFIX, DIGEST_KEY, arrays_digest
        except ImportError:  # code before checkpoints were bound (campaign.py --src): nothing to rebind
            BIND_PREFIX, DIGEST_KEY, arrays_digest = "checkpoint/", None, None
        p = newest(run, ".npz")
        with np.load(p) as z:
            arrays = {k: z[k] for k in z.files}
        bound = {k: v for k, v in arrays.items() if k.startswith(BIND_PREFIX)}
        new = fn({k: v for k, v in arrays.items() if k not in bound}) | (bound if rebind else {})
        with open(p, "wb") as fh:
            np.savez(fh, **new)
        if rebind and DIGEST_KEY and all(np.asarray(v).dtype != object for v in new.values()):
            j = newest(run, ".json")
            j.write_text(json.dumps({**json.loads(j.read_text()), DIGEST_KEY: arrays_digest(new)}))
    return f


def replace_with_file(rel):
    def f(run, tmp):
        shutil.rmtree(run / rel)
        (run / rel).write_text("not a directory")
    return f


def module(name, text):
    """An env module ``name`` in the test's ``mods`` directory (on ``sys.path`` in the test)."""
    def f(run, tmp):
        (tmp / "mods" / f"{name}.py").write_text(text)
    return f


def drop(key):
    def fn(d):
        d.pop(key)
        return d
    return fn


def nothing(run, tmp):
    pass
