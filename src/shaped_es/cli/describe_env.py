"""What ``shaped-es envs`` lists of each registered id (:func:`describe_env`): its presets, dims, time limit and
waypoint dimension, from one env made and reset, with MuJoCo's own warnings kept off the terminal
(:func:`quiet_mujoco`). ``check_env.py`` checks one env; this module lists many."""

from __future__ import annotations

import contextlib
import importlib
import importlib.util
import warnings

from shaped_es.cli.check_text import _line
from shaped_es.env_probe import BadOutput, waypoint_pair
from shaped_es.envs.core import POSITION_KEY, WAYPOINT_KEY


def describe_env(env_id: str) -> dict:
    """What ``shaped-es envs`` lists of a registered id: its presets (built-in envs), dims, time limit and
    waypoint dimension (None: no contract), from one env made and reset; ``error`` if it cannot be made."""
    from shaped_es.rollout import probe_env

    out = {"id": env_id, "presets": _presets(env_id), "obs": None, "act": None, "time_limit": None,
           "waypoints": None, "error": None}
    try:
        with warnings.catch_warnings(), quiet_mujoco():
            warnings.simplefilter("ignore")
            probe = probe_env(env_id, reset=True)
    except Exception as exc:  # noqa: BLE001 - listed with its reason (EnvSpecError mostly)
        out["error"] = _line(str(exc)).removeprefix(f"cannot make env {env_id!r}: ")
        return out
    info = probe.reset_info or {}
    out.update(obs=probe.obs_dim, act=probe.act_dim, time_limit=probe.time_limit)
    if probe.unbounded_action is not None:  # every method refuses it (policy_spec): not an env to list as usable
        out["error"] = f"an unbounded action space {probe.unbounded_action} (check-env says why)"
        return out
    if POSITION_KEY in info and WAYPOINT_KEY in info:
        try:  # the run's own reading of the pair: a 3-d position beside a 2-d waypoint is no contract (check-env's)
            out["waypoints"] = int(waypoint_pair(info)[0].shape[0])
        except BadOutput:
            out["waypoints"] = None
    return out


@contextlib.contextmanager
def quiet_mujoco():
    """MuJoCo's own warnings (e.g. Gymnasium's v4 models use a deprecated ``settotalmass``) go nowhere
    while inside: MuJoCo's default prints them to the terminal and appends them to ``MUJOCO_LOG.TXT`` in
    the working folder, which a listing of envs must not do. A no-op without MuJoCo."""
    if importlib.util.find_spec("mujoco") is None:
        yield
        return
    import mujoco

    old = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda msg: None)
    try:
        yield
    finally:
        mujoco.set_mju_user_warning(old)


def _presets(env_id: str) -> list[str]:
    from shaped_es.envs import BUILTIN

    if env_id not in BUILTIN:
        return []
    module = BUILTIN[env_id][0]  # its PRESETS: in the env's module, else in a config module beside it
    for name in (module, module.rsplit(".", 1)[0] + ".config"):
        try:
            presets = getattr(importlib.import_module(name), "PRESETS", None)
        except ImportError:
            continue
        if presets is not None:
            return sorted(presets)
    return []
