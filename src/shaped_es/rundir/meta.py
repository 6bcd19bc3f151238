"""What every run's checkpoint records about itself, whichever method trained it (ES trainer or PPO).

``Counters`` are the run's running totals (a checkpoint's meta holds them, and resume restores them);
``config_digest`` names the config fields that determine results, so a resume refuses a checkpoint that
another config made.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass

from shaped_es.config import RunConfig

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


@dataclass
class Counters:
    generation: int = 0  # generations completed
    env_steps: int = 0
    cpu_time_s: float = 0.0
    wall_time_s: float = 0.0
    best_test_reward: float = -math.inf
