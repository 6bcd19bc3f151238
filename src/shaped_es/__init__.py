"""shaped-es: shaped policy search with evolution strategies and waypoints (Lekkala & Itti).

Importing the package registers the built-in environments with Gymnasium, so
``gymnasium.make("shaped_es:CarNav-v0")`` works.
"""

from shaped_es.envs import register_envs as _register_envs

__version__ = "0.1.0"

_register_envs()
