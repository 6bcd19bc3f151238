"""Typed settings of CarlaNav-v0: the task CarNav-v0 shares (``NavTaskConfig``: episode, reward,
waypoint rules, observation scales, with the same defaults) plus the server, world and sensor settings.

Presets: ``paper`` (M = 1000 frames, routes of 1200-1800 m, i.e. 800-1200 waypoints at 1.5 m, the
paper's sizes) and ``default`` (M = 250, 90-180 m, as CarNav-v0's ``default``). Town07 by default.

Server address: ``host`` and ``port`` kwargs, else the environment variables ``SHAPED_ES_CARLA_HOST``
/ ``SHAPED_ES_CARLA_PORT``, else ``localhost:2000``. ``port`` is the *base* RPC port: a worker with
index ``i`` (``SHAPED_ES_WORKER_INDEX``, which the process executor sets for each of its workers; 0
elsewhere) talks to the server at ``port + 3 * i`` (a CARLA server on RPC port N also uses N+1 for
streaming and N+2 for its secondary servers, so servers step by 3).
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from shaped_es.envs.carnav.config import NavTaskConfig
from shaped_es.envs.presets import preset_config

ENV_ID = "CarlaNav-v0"
HOST_VAR, PORT_VAR = "SHAPED_ES_CARLA_HOST", "SHAPED_ES_CARLA_PORT"
WORKER_INDEX_VAR = "SHAPED_ES_WORKER_INDEX"  # set per worker by executors.process (WORKER_INDEX_ENV)
PORT_STEP = 3  # RPC port N, streaming N+1, secondary servers N+2
DEFAULT_HOST, DEFAULT_PORT = "localhost", 2000


@dataclass(frozen=True)
class CarlaNavConfig(NavTaskConfig):
    """CarlaNav-v0's numbers: the shared task (``NavTaskConfig``) and the CARLA side. Times in seconds."""

    # --- server ---
    host: str | None = None  # None: $SHAPED_ES_CARLA_HOST, else localhost
    port: int | None = None  # base RPC port; None: $SHAPED_ES_CARLA_PORT, else 2000
    worker_index: int | None = None  # None: $SHAPED_ES_WORKER_INDEX, else 0 (port = base + 3 * index)
    timeout_s: float = 10.0  # client timeout of every call and tick: a dead server raises within it
    load_timeout_s: float = 120.0  # client timeout while the server loads the town
    sensor_timeout_s: float = 10.0  # longest wait for the lidar measurement of a tick

    # --- world ---
    town: str = "Town07"  # the paper's town; loaded if the server runs another one
    no_rendering: bool = True  # no_rendering_mode (the ray-cast lidar works without rendering)
    vehicle: str = "vehicle.tesla.model3"  # blueprint id of the ego vehicle
    spawn_tries: int = 16  # start spawn points tried (seeded order) when one is blocked
    settle_ticks: int = 5  # braked ticks after spawning (the car drops onto the road), not steps

    # --- sensors ---
    lidar_height: float = 1.0  # lidar above the car's origin (ground): its one horizontal channel
    lidar_margin: float = 0.1  # points this close to the car's own box are dropped (self hits)

    env_id = ENV_ID

    def validate(self) -> "CarlaNavConfig":
        checks = self.task_checks() + [
            (self.port is None or 0 < int(self.port) < 65536 - PORT_STEP, "port must be in 1..65532"),
            (self.worker_index is None or int(self.worker_index) >= 0, "worker_index must be >= 0"),
            (min(self.timeout_s, self.load_timeout_s, self.sensor_timeout_s) > 0,
             "timeout_s, load_timeout_s and sensor_timeout_s must be positive"),
            (bool(self.town) and bool(self.vehicle), "town and vehicle must be named"),
            (self.spawn_tries >= 1 and self.settle_ticks >= 0, "spawn_tries >= 1 and settle_ticks >= 0"),
            (self.lidar_height > 0 and self.lidar_margin >= 0, "lidar_height > 0 and lidar_margin >= 0"),
        ]
        return self.check(("route_length",), checks)


PRESETS: dict[str, CarlaNavConfig] = {
    # Paper: M = 1000, 800-1200 waypoints at 1.5 m (1200-1800 m routes), Town07.
    "paper": CarlaNavConfig(max_steps=1000, route_length=(1200.0, 1800.0)),
    # As CarNav-v0's default: M = 250, 60-120 waypoints.
    "default": CarlaNavConfig(),
}


def make_config(preset: str = "default", **overrides: Any) -> CarlaNavConfig:
    """A preset with ``overrides`` applied (lists become tuples); one-line ``ValueError`` on bad input."""
    return preset_config(ENV_ID, PRESETS, preset, overrides)


def server_address(cfg: CarlaNavConfig, environ: Mapping[str, str] | None = None) -> tuple[str, int]:
    """``(host, rpc_port)`` of this worker's server: kwargs first, then the environment, then defaults;
    ``rpc_port = base + 3 * worker index``. One-line ``ValueError`` on a malformed variable."""
    env = os.environ if environ is None else environ
    host = cfg.host or env.get(HOST_VAR) or DEFAULT_HOST
    base = cfg.port if cfg.port is not None else _int_var(env, PORT_VAR, DEFAULT_PORT)
    index = cfg.worker_index if cfg.worker_index is not None else _int_var(env, WORKER_INDEX_VAR, 0)
    port = int(base) + PORT_STEP * int(index)
    if not 0 < port < 65536 or index < 0:
        raise ValueError(f"{ENV_ID}: port {base} + {PORT_STEP} x worker index {index} = {port} "
                         f"is not a TCP port")
    return host, port


def _int_var(env: Mapping[str, str], name: str, default: int) -> int:
    text = env.get(name, "").strip()
    if not text:
        return default
    try:
        return int(text)
    except ValueError:
        raise ValueError(f"{ENV_ID}: ${name} must be an integer, got {text!r}") from None
