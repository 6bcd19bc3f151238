"""What every run's checkpoint records about itself, whichever method trained it (ES trainer or PPO).

``Counters`` are the run's running totals (a checkpoint's meta holds them, and resume restores them);
``config_digest`` names the config fields that determine results, so a resume refuses a checkpoint that
another config made.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass

from shaped_es.config import RunConfig, read_yaml

# Fields that say where or how long a run executes, not what it computes: they may change on resume.
RUNTIME_FIELDS = ("generations", "executor", "workers", "address", "task_timeout_s", "max_retries",
                  "eval_overlap", "eval_workers", "clone_overlap", "checkpoint_every", "keep_checkpoints", "tensorboard", "stop_at", "wandb",
                  "video_every")


def config_digest(cfg: RunConfig) -> str:
    """Hash of the fields that determine results (not where or how the run executes)."""
    d = cfg.model_dump(mode="json")
    for k in RUNTIME_FIELDS:
        d.pop(k, None)
    return hashlib.sha256(repr(sorted(d.items())).encode()).hexdigest()[:16]


def settings_not_in(cfg: RunConfig, raw: dict) -> list[str]:
    """The dotted names of ``cfg``'s settings that a run's raw config.yaml ``raw`` does not have: settings
    a later shaped-es added (the run was made by an older version, whose digest had no such field)."""
    out: list[str] = []

    def walk(d: dict, r: dict, prefix: str) -> None:
        for k, v in d.items():
            if k not in r:
                out.append(prefix + k)
            elif isinstance(v, dict) and isinstance(r[k], dict):
                walk(v, r[k], f"{prefix}{k}.")

    walk(cfg.model_dump(mode="json"), raw if isinstance(raw, dict) else {}, "")
    return out


def older_version_hint(cfg: RunConfig, config_path) -> str:
    """Why a checkpoint's digest can differ although ``config_path`` (the run's config.yaml) built ``cfg``:
    settings this shaped-es has and that file lacks, i.e. a run made by an older version ("" if none)."""
    try:
        new = settings_not_in(cfg, read_yaml(config_path))
    except Exception:  # noqa: BLE001 - only the message's detail: the error itself stands
        return ""
    if not new:
        return ""
    more = f" (+{len(new) - 3} more)" if len(new) > 3 else ""
    return (f": the run was made by an older shaped-es, without the settings {', '.join(new[:3])}{more}; "
            f"finish it with that version, or start a new run")


def checkpoint_mismatch(meta: dict, cfg: RunConfig, method: str, config_path) -> str | None:
    """None when a checkpoint's ``meta`` was made by ``cfg`` (its digest) and ``method``; else the detail
    for the refusal's message (:func:`older_version_hint`, possibly "")."""
    if meta.get("method", method) == method and meta.get("config_digest") == config_digest(cfg):
        return None
    return older_version_hint(cfg, config_path)


@dataclass
class Counters:
    generation: int = 0  # generations completed
    env_steps: int = 0
    cpu_time_s: float = 0.0
    wall_time_s: float = 0.0
    best_test_reward: float = -math.inf
