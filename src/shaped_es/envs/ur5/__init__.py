"""UR5Reach-v0: a UR5 arm following quadratic-Bezier waypoints in MuJoCo (the paper's Gazebo arm task).

Modules: ``config`` (typed presets), ``kinematics`` (published UR5 DH forward kinematics), ``bezier``
(waypoints), ``core`` (batched MuJoCo core), ``env`` (Gymnasium ``UR5ReachEnv``), ``controller`` (a
hand-written waypoint follower), ``render`` (offscreen frames), ``ur5.xml`` (the MJCF model).

Offscreen rendering needs ``MUJOCO_GL`` set before ``mujoco`` is imported. When it is unset, there is no
display (where the default GLFW backend cannot work) and ``mujoco`` is not imported yet, this package
sets it to ``egl`` (headless; apt packages ``libegl1 libgl1-mesa-dri``). See ``render.py``.
"""

import ctypes.util
import os
import sys

from shaped_es.envs.gl import headless_gl

if "mujoco" not in sys.modules:
    headless_gl()
    if os.environ.get("MUJOCO_GL", "").lower().strip() == "osmesa" and ctypes.util.find_library("OSMesa") is None:
        # mujoco's own import would die in PyOpenGL with an AttributeError; say what is missing instead
        raise ImportError("MUJOCO_GL=osmesa but libOSMesa is not installed: apt-get install libosmesa6, "
                          "or use MUJOCO_GL=egl (apt-get install libegl1 libgl1-mesa-dri)")
