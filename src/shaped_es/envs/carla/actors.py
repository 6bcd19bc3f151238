"""The actors of one CarlaNav-v0 episode: the ego vehicle, its lidar and its collision sensor.

Sensor data arrives on the client's threads: the lidar's measurements go into a queue the env reads
after each tick, waiting at most ``sensor_timeout_s`` for the measurement of that tick's frame (a
server that stops sending raises :class:`~shaped_es.envs.carla.connection.CarlaServerLost`, never
hangs); collision events are kept with their frame and counted at the step whose frame reaches them.
:meth:`EgoActors.destroy` stops both sensors, then destroys them and the vehicle (sensors first).
"""

from __future__ import annotations

import queue
import threading
import time
from typing import Any

import numpy as np

from shaped_es.envs.carla.config import ENV_ID, CarlaNavConfig
from shaped_es.envs.carla.connection import ROLE_NAME, CarlaServerLost, Session
from shaped_es.envs.carla.lidar import LIDAR_BLUEPRINT, bin_ranges, lidar_attributes, points_of

COLLISION_BLUEPRINT = "sensor.other.collision"


def _blueprint(session: Session, name: str, attributes: dict[str, str]) -> Any:
    bp = session.world.get_blueprint_library().find(name)
    for key, value in {**attributes, "role_name": ROLE_NAME}.items():
        if bp.has_attribute(key):
            bp.set_attribute(key, value)
    return bp


class EgoActors:
    """The ego vehicle with a 32-beam lidar at its box centre and a collision sensor."""

    def __init__(self, session: Session, vehicle: Any, cfg: CarlaNavConfig):
        carla = session.carla
        self.session, self.vehicle, self.cfg = session, vehicle, cfg
        self.lidar = self.collision = None
        self._scans: queue.Queue = queue.Queue()
        self._hits: list[int] = []  # frames of collision events
        self._lock = threading.Lock()
        box = vehicle.bounding_box
        self.half = (float(box.extent.x), float(box.extent.y))  # half length, half width (m)
        mount = carla.Transform(carla.Location(x=float(box.location.x), y=float(box.location.y),
                                               z=cfg.lidar_height))
        try:
            self.lidar = session.world.spawn_actor(
                _blueprint(session, LIDAR_BLUEPRINT, lidar_attributes(cfg.lidar_beams, cfg.dt, cfg.lidar_range)),
                mount, attach_to=vehicle)
            self.lidar.listen(self._scans.put)
            self.collision = session.world.spawn_actor(_blueprint(session, COLLISION_BLUEPRINT, {}),
                                                       carla.Transform(), attach_to=vehicle)
            self.collision.listen(self._on_collision)
        except BaseException:
            self.destroy()
            raise

    @classmethod
    def spawn(cls, session: Session, transform: Any, cfg: CarlaNavConfig) -> "EgoActors | None":
        """The ego at ``transform`` with its sensors, or None if the spot is blocked."""
        bp = _blueprint(session, cfg.vehicle, {})
        vehicle = session.world.try_spawn_actor(bp, transform)
        return None if vehicle is None else cls(session, vehicle, cfg)

    def _on_collision(self, event: Any) -> None:
        with self._lock:
            self._hits.append(int(event.frame))

    def collided(self, frame: int) -> bool:
        """True if a collision event of a frame up to ``frame`` arrived since the last call."""
        with self._lock:
            hit = any(f <= frame for f in self._hits)
            self._hits = [f for f in self._hits if f > frame]
        return hit

    def ranges(self, frame: int) -> np.ndarray:
        """The 32 beam ranges ``(beams,)`` (m) of the lidar measurement of ``frame`` (older ones are
        skipped); :class:`CarlaServerLost` if it does not arrive within ``sensor_timeout_s``."""
        deadline = time.monotonic() + self.cfg.sensor_timeout_s
        while True:
            try:
                scan = self._scans.get(timeout=max(0.0, deadline - time.monotonic()))
            except queue.Empty:
                raise CarlaServerLost(f"{ENV_ID}: no lidar data for frame {frame} from the CARLA server at "
                                      f"{self.session.address} within {self.cfg.sensor_timeout_s:g} s") from None
            if int(scan.frame) >= frame:
                break
        return bin_ranges(points_of(scan.raw_data), self.cfg.lidar_beams, self.cfg.lidar_range, self.half,
                          self.cfg.lidar_margin)

    def destroy(self) -> None:
        """Stop the sensors, then destroy them and the vehicle; idempotent."""
        sensors = [s for s in (self.lidar, self.collision) if s is not None]
        for sensor in sensors:
            if sensor.is_listening():
                sensor.stop()
        for actor in sensors + ([self.vehicle] if self.vehicle is not None else []):
            actor.destroy()
        self.lidar = self.collision = self.vehicle = None
