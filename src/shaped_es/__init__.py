"""shaped-es: shaped policy search with evolution strategies and waypoints (Lekkala & Itti).

Importing the package registers the built-in environments with Gymnasium, so
``gymnasium.make("shaped_es:CarNav-v0")`` works. ``load_policy(run_dir)`` loads a trained policy
(``shaped_es.trained.load``), ``evaluation_seeds`` gives ``shaped-es evaluate``'s episode seeds, and
``train(config, out, callback=...)`` starts a run from Python (``shaped_es.api``); all are imported on
first use, so ``import shaped_es`` stays light for workers.
"""

from shaped_es.envs import register_envs as _register_envs

__version__ = "0.1.0"

_register_envs()

_LAZY = {"load_policy": "shaped_es.trained.load", "Policy": "shaped_es.trained.load", "train": "shaped_es.api",
         "RunConfig": "shaped_es.config", "Callback": "shaped_es.monitor.callbacks",
         "evaluation_seeds": "shaped_es.seeding"}
__all__ = ["Callback", "Policy", "RunConfig", "__version__", "evaluation_seeds", "load_policy", "train"]


def __getattr__(name: str):
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'shaped_es' has no attribute {name!r}")
