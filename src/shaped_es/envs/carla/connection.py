"""The connection to one CARLA server: the lazy ``carla`` import, the version check, the world's
settings (synchronous, fixed step, no rendering) and their restoration, and the tick.

One :class:`Session` per server per process, shared by every CarlaNav-v0 env of the process that talks
to it (the probe env, the rollout's env, PPO's train and test envs), because the settings to restore are
the ones the server had before the first of them connected. Only one env drives the world at a time:
an env that resets :meth:`~Session.claim` s the world, which ends the episode of the env that had it
(its actors are destroyed; stepping it raises until it resets).

Faults: every call runs under the client timeout (``timeout_s``), so a dead server raises
:class:`CarlaServerLost` (a *worker fault*: ``worker_fault = True``; the Ray executor retries the task,
the process executor stops the run with one line and the resume command) instead of hanging. A tick
whose frame is not the previous one + 1 means another client ticks the same server (two workers on
one port): a one-line :class:`CarlaError`. Actors are tagged with :data:`ROLE_NAME`; the ones a killed
worker left behind are destroyed when the next session connects.
"""

from __future__ import annotations

import multiprocessing.util
from typing import Any

from shaped_es.envs.carla.config import ENV_ID, CarlaNavConfig

CARLA_VERSION = "0.9.16"  # the client the extra pins; it must match the server's version
INSTALL_HINT = "pip install -e '.[carla]'"
ROLE_NAME = "shaped_es"  # role_name of every actor the env spawns
CLEANUP_TIMEOUT_S = 1.0  # client timeout of the best-effort clean-up after a lost server


class CarlaMissing(ModuleNotFoundError):
    """The ``carla`` client package is not installed (or its library does not load)."""


class CarlaError(RuntimeError):
    """A CARLA server cannot be used as asked (wrong version, busy, no spawn point): one line."""


class CarlaServerLost(CarlaError):
    """No CARLA server answers (at connect, or mid-episode within the timeouts): a worker fault."""

    worker_fault = True  # read by the executors and the command line (a lost server, not a bug)


def import_carla() -> Any:
    """The ``carla`` module; one line with the install command when it is missing."""
    try:
        import carla
    except ImportError as exc:
        raise CarlaMissing(f"{ENV_ID} needs the CARLA {CARLA_VERSION} client (the 'carla' package, "
                           f"{type(exc).__name__}: {exc}): {INSTALL_HINT}") from None
    return carla


def first_line(exc: BaseException) -> str:
    lines = str(exc).strip().splitlines()
    return lines[0] if lines else type(exc).__name__


def _release(version: str) -> str:
    """``"0.9.16"`` of ``"0.9.16-12-gabc"`` / ``"0.9.16"`` (the part the client and server must share)."""
    return version.strip().split("-")[0]


def _map_name(name: str) -> str:
    return name.rstrip("/").rsplit("/", 1)[-1]


class Session:
    """One server's client, world, map and original settings (see the module docstring)."""

    def __init__(self, carla: Any, host: str, port: int, cfg: CarlaNavConfig):
        self.carla, self.address, self.timeout_s = carla, f"{host}:{port}", cfg.timeout_s
        self.users: set = set()  # envs holding this session
        self.active: Any = None  # the env whose episode owns the world
        self.frame: int | None = None
        self.original = None
        self.closed = False
        self.cache: dict[str, Any] = {}  # per-map data of the envs (road graph, spawn points)
        try:
            self.client = carla.Client(host, port)
            self.client.set_timeout(cfg.timeout_s)
            server = self.client.get_server_version()
        except RuntimeError as exc:
            raise CarlaServerLost(f"{ENV_ID}: no CARLA server answers at {self.address} within "
                                  f"{cfg.timeout_s:g} s ({first_line(exc)}); start one (README, Real CARLA)"
                                  ) from None
        client = self.client.get_client_version()
        if _release(server) != _release(client):
            raise CarlaError(f"{ENV_ID}: the CARLA server at {self.address} runs {server} but the client is "
                             f"{client}; they must match: pip install carla=={_release(server)}")
        try:
            self._open_world(cfg)
        except RuntimeError as exc:
            self.restore()
            raise CarlaServerLost(f"{ENV_ID}: the CARLA server at {self.address} stopped answering while "
                                  f"setting up {cfg.town} ({first_line(exc)})") from None
        _OPEN[self.address] = self

    def _open_world(self, cfg: CarlaNavConfig) -> None:
        world = self.client.get_world()
        if _map_name(world.get_map().name) != _map_name(cfg.town):
            self.client.set_timeout(cfg.load_timeout_s)
            world = self.client.load_world(cfg.town)
            self.client.set_timeout(cfg.timeout_s)
        self.world = world
        stale = [a for a in world.get_actors() if a.attributes.get("role_name") == ROLE_NAME]
        for actor in sorted(stale, key=lambda a: not a.type_id.startswith("sensor.")):  # sensors first
            actor.destroy()
        self.original = world.get_settings()
        ours = world.get_settings()
        ours.synchronous_mode = True
        ours.fixed_delta_seconds = cfg.dt
        ours.no_rendering_mode = cfg.no_rendering
        world.apply_settings(ours)
        self.map = world.get_map()

    def tick(self) -> int:
        """One synchronous step of the world; the new frame id."""
        frame = int(self.world.tick(self.timeout_s))
        if self.frame is not None and frame != self.frame + 1:
            raise CarlaError(f"{ENV_ID}: another client ticks the CARLA server at {self.address} (frame "
                             f"{self.frame} -> {frame}); give every worker its own server (README, Real CARLA)")
        self.frame = frame
        return frame

    def claim(self, env: Any) -> None:
        """``env`` starts an episode: the env that drove the world before ends its episode."""
        if self.active is not None and self.active is not env:
            self.active.preempt()
        self.active = env

    def restore(self) -> None:
        """Give the server back the settings it had (best effort: the server may be gone)."""
        if self.original is not None:
            try:
                self.world.apply_settings(self.original)
            except RuntimeError:
                pass
            self.original = None

    def close(self, lost: bool = False) -> None:
        """End every user's episode, restore the settings and forget the session. ``lost``: the server
        stopped answering, so the clean-up gets a short timeout."""
        if self.closed:
            return
        self.closed = True
        _OPEN.pop(self.address, None)
        if lost:
            self.client.set_timeout(CLEANUP_TIMEOUT_S)
        for env in list(self.users):
            env.preempt()
        self.restore()


_OPEN: dict[str, Session] = {}  # address -> the open session of this process


def acquire(carla: Any, host: str, port: int, cfg: CarlaNavConfig, env: Any) -> Session:
    """The open session to ``host:port`` (connected now if there is none), with ``env`` as a user."""
    session = _OPEN.get(f"{host}:{port}")
    if session is None or session.closed:
        session = Session(carla, host, port, cfg)
    session.users.add(env)
    return session


def release(session: Session, env: Any) -> None:
    """``env`` is done with ``session``; the last user restores the server's settings."""
    session.users.discard(env)
    if session.active is env:
        session.active = None
    if not session.users:
        session.close()


def close_all() -> None:
    """Close every open session (at interpreter or worker exit: envs cached by the rollout layer are
    never closed, and the server must not stay in synchronous mode)."""
    for session in list(_OPEN.values()):
        session.close()


# Runs at exit in the main process and in multiprocessing workers alike (atexit does not run in the latter).
multiprocessing.util.Finalize(None, close_all, exitpriority=10)
