"""The label probe's result on disk: ``RUN/label_probe.json`` (``label_probe.ProbeResult``, checked field by
field when read) and its best simulated candidate beside it (``probe_candidate.FILE``), so a resumed run (or
one restarted in generation 0) reuses the probe instead of probing again."""

from __future__ import annotations

import json
from dataclasses import asdict, fields
from pathlib import Path

import numpy as np

from shaped_es.config import ConfigError, RunConfig
from shaped_es.guides import probe_candidate
from shaped_es.guides.label_probe import ProbeResult, probe
from shaped_es.policies import MLPSpec, ObsStats
from shaped_es.rundir.atomic import StoreError, atomic_write_text, read_regular
from shaped_es.shaping.settings import InverseDynamicsConfig

FILE = "label_probe.json"


def parse(raw: bytes) -> ProbeResult:
    """A saved probe, checked field by field (``ValueError`` naming the first bad one)."""
    d = json.loads(raw.decode())
    if not isinstance(d, dict):
        raise ValueError("not a JSON object")
    known = {f.name for f in fields(ProbeResult)} - {"candidate_params"}
    if set(d) - known or {"frame", "query_clip", "returns", "env_steps", "seconds", "reason"} - set(d):
        raise ValueError(f"fields {sorted(d)}")
    clip, steps = d["query_clip"], d["env_steps"]
    checks = [
        (d["frame"] in ("both", "world"), "frame"),
        (clip is None or (isinstance(clip, (int, float)) and not isinstance(clip, bool) and clip > 0), "query_clip"),
        (isinstance(d["returns"], dict) and all(isinstance(v, list) for v in d["returns"].values()), "returns"),
        (isinstance(steps, int) and not isinstance(steps, bool) and steps >= 0, "env_steps"),
        (isinstance(d["seconds"], (int, float)) and isinstance(d["reason"], str), "seconds/reason"),
        (isinstance(d.get("zero_action", []), list), "zero_action"),
        (isinstance(d.get("clones", {}), dict) and all(isinstance(v, list) for v in d.get("clones", {}).values()),
         "clones"),
        (isinstance(d.get("shoot", []), list), "shoot"),
        (d.get("shoot_on") is None or isinstance(d.get("shoot_on"), bool), "shoot_on"),
        (d.get("shoot_horizon") is None or (type(d.get("shoot_horizon")) is int and 1 <= d["shoot_horizon"] <= 64),
         "shoot_horizon"),
        (isinstance(d.get("shoot_tried", {}), dict)
         and all(isinstance(v, list) for v in d.get("shoot_tried", {}).values()), "shoot_tried"),
        (d.get("candidate") is None or isinstance(d.get("candidate"), str), "candidate"),
        (d.get("chunk") is None or (type(d.get("chunk")) is int and 1 <= d["chunk"] <= 64), "chunk"),
        (isinstance(d.get("passed", []), list) and all(isinstance(v, str) for v in d.get("passed", [])), "passed"),
        (d.get("obs_stats") is None or _stats_ok(d["obs_stats"]), "obs_stats"),
        (d.get("shoot_frame") in (None, "world", "waypoint"), "shoot_frame"),
        (d.get("step_change") is None or isinstance(d.get("step_change"), bool), "step_change"),
        (_errors_ok(d.get("step_change_errors", {})), "step_change_errors"),
        (_errors_ok(d.get("shoot_frame_errors", {})), "shoot_frame_errors"),
    ]
    bad = next((name for ok, name in checks if not ok), None)
    if bad is not None:
        raise ValueError(f"bad {bad}")
    return ProbeResult(**d)


def _errors_ok(errors) -> bool:
    """A probe's table of held-out errors (``shoot_frame_errors``, ``step_change_errors``): name -> a number."""
    return isinstance(errors, dict) and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                            for v in errors.values())


def seconds_in(root: Path) -> float:
    """The label probe's wall seconds as ``RUN/label_probe.json`` records them (0.0: no probe file, or one that
    cannot be read: only a report's detail reads this)."""
    try:
        return float(parse(read_regular(Path(root) / FILE)).seconds)
    except (OSError, ValueError, StoreError, TypeError):
        return 0.0


def _stats_ok(v) -> bool:
    """``[count, mean, m2]``: a positive count and two equal-length lists of finite numbers, m2 >= 0."""
    if not (isinstance(v, list) and len(v) == 3 and isinstance(v[0], (int, float)) and not isinstance(v[0], bool)
            and v[0] > 0 and all(isinstance(x, list) and x for x in v[1:]) and len(v[1]) == len(v[2])):
        return False
    try:
        mean, m2 = np.asarray(v[1], np.float64), np.asarray(v[2], np.float64)
    except (TypeError, ValueError):
        return False
    return bool(mean.ndim == 1 and np.isfinite(mean).all() and np.isfinite(m2).all() and (m2 >= 0).all())


def start_stats(res: ProbeResult, obs_dim: int) -> ObsStats | None:
    """The probe's observation statistics (``es.obs_norm``) as the run's starting ones (None: none kept, or of
    another observation size: the run then starts from none, as before)."""
    if res.obs_stats is None or len(res.obs_stats[1]) != obs_dim:
        return None
    count, mean, m2 = res.obs_stats
    return ObsStats(float(count), np.asarray(mean, np.float64), np.asarray(m2, np.float64))


def load_or_probe(path: Path, cfg: RunConfig, spec: MLPSpec, pos_dim: int,
                  mphi_cfg: InverseDynamicsConfig, executor=None, say=None) -> tuple[ProbeResult, bool]:
    """``(result, fresh)``: the run's saved probe (a resumed run) or a new one, saved at ``path`` (``say``: where a
    long probe's progress lines go, ``label_probe.Pace``)."""
    if path.exists() or path.is_symlink():
        try:
            res = parse(read_regular(path))
        except (ValueError, TypeError, UnicodeDecodeError, OSError, StoreError) as exc:
            raise ConfigError(f"{path} is not a label probe this version wrote ({exc}); move it away to probe "
                              f"again (the new probe's env steps then count in the next generation)") from None
        if res.candidate is not None:  # kept beside it; a probe from before has none
            res.candidate_params = probe_candidate.load(path.with_name(probe_candidate.FILE), spec.num_params)
        return res, False
    res = probe(cfg, spec, pos_dim, mphi_cfg, executor, say)
    if res.candidate_params is not None:  # first: a probe file on disk always has its candidate beside it
        probe_candidate.save(path.with_name(probe_candidate.FILE), res.candidate_params)
    atomic_write_text(path, json.dumps({k: v for k, v in asdict(res).items() if k != "candidate_params"}, indent=1))
    return res, True
