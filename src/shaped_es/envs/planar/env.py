"""The Gymnasium side every planar body shares: ``PlanarEnv`` (the ``BatchCoreEnv`` base of the three),
``config_maker`` (a body's ``make_config`` over its ``PRESETS``) and ``entry_points`` (its registered
``make_limited`` and ``vector_entry_point``), so a body module declares only its config, core and env."""

from __future__ import annotations

from typing import Any, Callable, ClassVar

from shaped_es.envs.batch_env import BatchCoreEnv
from shaped_es.envs.core import limited_entry_point
from shaped_es.envs.planar.task import PlanarTaskConfig
from shaped_es.envs.presets import preset_config
from shaped_es.envs.vector import vector_entry_point


class PlanarEnv(BatchCoreEnv):
    """``BatchCoreEnv`` of a planar body; a subclass sets ``env_id``, ``core_cls`` and ``make_config``."""

    metadata: ClassVar[dict[str, Any]] = {"render_modes": [], "render_fps": 10}


def config_maker(env_id: str, presets: dict[str, PlanarTaskConfig]) -> Callable[..., PlanarTaskConfig]:
    """The body's ``make_config(preset="default", **overrides)``: ``presets[preset]`` with ``overrides``
    applied and validated (``envs/presets.py``)."""

    def make_config(preset: str = "default", **overrides: Any) -> PlanarTaskConfig:
        return preset_config(env_id, presets, preset, overrides)

    make_config.__doc__ = f"{env_id}'s config: a preset of {sorted(presets)} with keyword overrides."
    return make_config


def entry_points(env_cls: type[PlanarEnv]) -> tuple[Callable[..., Any], Callable[..., Any]]:
    """``(make_limited, VectorEnv)`` of ``env_cls``: the registered entry point and ``vector_entry_point``
    (``envs.BUILTIN``)."""
    return limited_entry_point(env_cls), vector_entry_point(env_cls)
