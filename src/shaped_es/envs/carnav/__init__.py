"""CarNav-v0: a fast embedded driving simulator for waypoint navigation (the paper's CARLA Town07 task).

Modules: ``config`` (typed presets; the task shared with CarlaNav-v0), ``observation`` (the shared
observation terms and scales), ``town`` (procedural towns, packed), ``planner`` (A*, routes and
global waypoints), ``waypoints`` (reached / skipped / local waypoint rules), ``lidar`` (Numba lidar and
collision kernels), ``vehicle`` (kinematic bicycle), ``core`` (the batched core), ``env`` (the Gymnasium
``CarNavEnv``), ``render`` (top-down ``rgb_array``).
"""

from shaped_es.envs.carnav.config import PRESETS, CarNavConfig, make_config

__all__ = ["PRESETS", "CarNavConfig", "make_config"]
