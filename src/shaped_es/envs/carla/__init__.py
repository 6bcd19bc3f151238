"""CarlaNav-v0: the paper's driving task on a real CARLA 0.9.16 server (optional extra ``carla``).

Modules: ``config`` (typed presets, the server address and per-worker port), ``connection`` (the lazy
``carla`` import, version check, world settings and their restoration, ticks, faults), ``routes``
(the global planner: A* over ``Map.get_topology()``), ``lidar`` (sensor attributes, binning into 32
beams), ``frame`` (CARLA's left-handed frame to CarNav-v0's), ``terms`` (controls, waypoint progress,
reward and observation: CarNav-v0's rules), ``actors`` (the ego vehicle and its sensors), ``env`` (the
Gymnasium ``CarlaNavEnv``). Nothing here imports ``carla`` at import time.
"""

from shaped_es.envs.carla.config import PRESETS, CarlaNavConfig, make_config

__all__ = ["PRESETS", "CarlaNavConfig", "make_config"]
