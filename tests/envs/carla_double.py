"""A TEST DOUBLE of the ``carla`` client API subset CarlaNav-v0 calls, with an in-process "server".

Not CARLA: a tiny deterministic world that keeps CARLA's interfaces and conventions so the env's use of
them is checked without a server -- the left-handed frame (y right, yaw in degrees clockwise seen from
above, angular velocity in deg/s), synchronous ticks returning frame ids, sensors that call ``listen``
callbacks with ``LidarMeasurement`` (``raw_data``: float32 x, y, z, intensity in the sensor frame) and
``CollisionEvent`` objects, ``Map.get_topology()`` (entry, exit) waypoint pairs and ``Waypoint.next(d)``
that continues into the successor lanes. Blueprints accept only the attribute names the real
blueprints have (a typo raises, as ``set_attribute`` does on a server). Every server call is logged in
``FakeServer.log`` so tests can check the order (settings, ticks, listen/stop/destroy).

Faults: ``dead`` (every call raises the client's ``RuntimeError`` time-out at once), ``lidar_silent``
(ticks succeed, the lidar sends nothing), ``rogue_ticks`` (another client ticks too: frames jump).

Road network (CARLA coordinates, metres): a 100 x 60 loop driven clockwise on the map (x east, y south)
with a two-way middle road at x = 50; posts (obstacles) are cylinders.
"""

from __future__ import annotations

import math
import types
from dataclasses import dataclass, field

import numpy as np

TIMEOUT_TEXT = "time-out of {ms}ms while waiting for the simulator, make sure the simulator is ready and connected to {addr}"

LANES = [  # (start, end) in CARLA coordinates; each lane is one road of the topology
    ((0.0, 0.0), (50.0, 0.0)), ((50.0, 0.0), (100.0, 0.0)), ((100.0, 0.0), (100.0, 60.0)),
    ((100.0, 60.0), (50.0, 60.0)), ((50.0, 60.0), (0.0, 60.0)), ((0.0, 60.0), (0.0, 0.0)),
    ((50.0, 0.0), (50.0, 60.0)), ((50.0, 60.0), (50.0, 0.0)),
]
SPAWNS = [(0, 10.0), (1, 20.0), (2, 30.0), (3, 20.0), (4, 30.0), (5, 30.0)]  # (lane, s)
LIDAR_ATTRS = {"channels", "range", "points_per_second", "rotation_frequency", "upper_fov", "lower_fov",
               "horizontal_fov", "atmosphere_attenuation_rate", "dropoff_general_rate",
               "dropoff_intensity_limit", "dropoff_zero_intensity", "noise_stddev", "sensor_tick", "role_name"}
BLUEPRINT_ATTRS = {"sensor.lidar.ray_cast": LIDAR_ATTRS, "sensor.other.collision": {"role_name"},
                   "vehicle.tesla.model3": {"role_name", "color"}}


# -- geometry values (client-side classes) ------------------------------------------------------------
@dataclass
class Vector3D:
    x: float = 0.0
    y: float = 0.0
    z: float = 0.0


class Location(Vector3D):
    def distance(self, other: "Location") -> float:
        return math.dist((self.x, self.y, self.z), (other.x, other.y, other.z))


@dataclass
class Rotation:
    pitch: float = 0.0
    yaw: float = 0.0
    roll: float = 0.0


@dataclass
class Transform:
    location: Location = field(default_factory=Location)
    rotation: Rotation = field(default_factory=Rotation)


@dataclass
class VehicleControl:
    throttle: float = 0.0
    steer: float = 0.0
    brake: float = 0.0
    hand_brake: bool = False
    reverse: bool = False


@dataclass
class WorldSettings:
    synchronous_mode: bool = False
    no_rendering_mode: bool = False
    fixed_delta_seconds: float | None = None


@dataclass
class BoundingBox:
    location: Location
    extent: Vector3D


@dataclass
class LidarMeasurement:
    frame: int
    raw_data: bytes


@dataclass
class CollisionEvent:
    frame: int
    other_actor: object = None


# -- the map ------------------------------------------------------------------------------------------
def _lane_len(i: int) -> float:
    (x0, y0), (x1, y1) = LANES[i]
    return math.hypot(x1 - x0, y1 - y0)


class Waypoint:
    def __init__(self, lane: int, s: float):
        self.lane, self.s = lane, min(max(s, 0.0), _lane_len(lane))
        (x0, y0), (x1, y1) = LANES[lane]
        t = self.s / _lane_len(lane)
        self.transform = Transform(Location(x0 + t * (x1 - x0), y0 + t * (y1 - y0), 0.0),
                                   Rotation(yaw=math.degrees(math.atan2(y1 - y0, x1 - x0))))
        self.road_id, self.section_id, self.lane_id = lane + 1, 0, -1

    def next(self, d: float) -> list["Waypoint"]:
        rest = _lane_len(self.lane) - self.s
        if d <= rest + 1e-9:
            return [Waypoint(self.lane, self.s + d)]
        end = LANES[self.lane][1]
        return [w for j, lane in enumerate(LANES) if lane[0] == end and LANES[j][1] != LANES[self.lane][0]
                for w in Waypoint(j, 0.0).next(d - rest)]


class Map:
    name = "Carla/Maps/Town07"

    def get_topology(self):
        return [(Waypoint(i, 0.0), Waypoint(i, _lane_len(i))) for i in range(len(LANES))]

    def get_spawn_points(self):
        out = []
        for lane, s in SPAWNS:
            t = Waypoint(lane, s).transform
            out.append(Transform(Location(t.location.x, t.location.y, 0.5), Rotation(yaw=t.rotation.yaw)))
        return out

    def get_waypoint(self, location, project_to_road=True, lane_type=None):
        best = None
        for i, ((x0, y0), (x1, y1)) in enumerate(LANES):
            L = _lane_len(i)
            s = min(max(((location.x - x0) * (x1 - x0) + (location.y - y0) * (y1 - y0)) / L, 0.0), L)
            w = Waypoint(i, s)
            d = math.hypot(w.transform.location.x - location.x, w.transform.location.y - location.y)
            if best is None or d < best[0] - 1e-9:
                best = (d, w)
        return best[1]


# -- actors -------------------------------------------------------------------------------------------
class ActorBlueprint:
    def __init__(self, bp_id: str):
        self.id, self.attributes = bp_id, {}

    def has_attribute(self, name: str) -> bool:
        return name in BLUEPRINT_ATTRS[self.id]

    def set_attribute(self, name: str, value: str) -> None:
        if not self.has_attribute(name):
            raise IndexError(f"blueprint {self.id} has no attribute {name!r}")
        if not isinstance(value, str):
            raise TypeError("set_attribute takes a string")
        self.attributes[name] = value


class BlueprintLibrary:
    def __init__(self, server):
        self.server = server

    def find(self, bp_id: str) -> ActorBlueprint:
        self.server.call(f"find {bp_id}")
        if bp_id not in BLUEPRINT_ATTRS:
            raise IndexError(f"no blueprint {bp_id!r}")
        return ActorBlueprint(bp_id)


class Actor:
    def __init__(self, server, bp: ActorBlueprint, transform: Transform, parent=None):
        server.next_id += 1
        self.server, self.id, self.type_id, self.parent = server, server.next_id, bp.id, parent
        self.attributes = dict(bp.attributes)
        self.blueprint_attributes = dict(bp.attributes)
        self.local = transform
        self.alive = True

    def destroy(self) -> bool:
        self.server.call(f"destroy {self.type_id}")
        self.alive = False
        self.server.actors.pop(self.id, None)
        return True

    def is_alive(self) -> bool:
        return self.alive


class Vehicle(Actor):
    bounding_box = BoundingBox(Location(0.0, 0.0, 0.7), Vector3D(2.4, 1.0, 0.75))

    def __init__(self, server, bp, transform):
        super().__init__(server, bp, transform)
        self.x, self.y, self.yaw = transform.location.x, transform.location.y, transform.rotation.yaw
        self.speed, self.yaw_rate, self.control = 0.0, 0.0, VehicleControl()

    def apply_control(self, control: VehicleControl) -> None:
        self.server.call("apply_control")
        self.control = control

    def get_transform(self) -> Transform:  # client-side in CARLA: last tick's values
        return Transform(Location(self.x, self.y, 0.0), Rotation(yaw=self.yaw))

    def get_velocity(self) -> Vector3D:
        r = math.radians(self.yaw)
        return Vector3D(self.speed * math.cos(r), self.speed * math.sin(r), 0.0)

    def get_angular_velocity(self) -> Vector3D:
        return Vector3D(0.0, 0.0, self.yaw_rate)  # deg/s, + clockwise seen from above

    def physics(self, dt: float) -> None:
        c = self.control
        self.speed = max(0.0, self.speed + (3.0 * c.throttle - 8.0 * c.brake) * dt)
        self.yaw_rate = 8.0 * c.steer * self.speed  # deg/s: steer + turns right (yaw grows)
        self.yaw = (self.yaw + self.yaw_rate * dt + 180.0) % 360.0 - 180.0
        r = math.radians(self.yaw)
        self.x += self.speed * math.cos(r) * dt
        self.y += self.speed * math.sin(r) * dt


class Sensor(Actor):
    def __init__(self, server, bp, transform, parent):
        super().__init__(server, bp, transform, parent)
        self.callback = None

    def listen(self, callback) -> None:
        self.server.call(f"listen {self.type_id}")
        self.callback = callback

    def stop(self) -> None:
        self.server.call(f"stop {self.type_id}")
        self.callback = None

    def is_listening(self) -> bool:
        return self.callback is not None


# -- the world and the server -------------------------------------------------------------------------
class World:
    def __init__(self, server):
        self.server = server

    def get_map(self) -> Map:
        self.server.call("get_map")
        return self.server.map

    def get_settings(self) -> WorldSettings:
        self.server.call("get_settings")
        s = self.server.settings
        return WorldSettings(s.synchronous_mode, s.no_rendering_mode, s.fixed_delta_seconds)

    def apply_settings(self, settings: WorldSettings) -> int:
        self.server.call(f"apply_settings sync={settings.synchronous_mode} dt={settings.fixed_delta_seconds} "
                         f"no_render={settings.no_rendering_mode}")
        self.server.settings = WorldSettings(settings.synchronous_mode, settings.no_rendering_mode,
                                             settings.fixed_delta_seconds)
        return self.server.frame

    def get_blueprint_library(self) -> BlueprintLibrary:
        return BlueprintLibrary(self.server)

    def get_actors(self):
        self.server.call("get_actors")
        return list(self.server.actors.values())

    def try_spawn_actor(self, bp, transform):
        self.server.call(f"try_spawn {bp.id}")
        loc = transform.location
        for a in self.server.actors.values():
            if isinstance(a, Vehicle) and math.hypot(a.x - loc.x, a.y - loc.y) < 3.0:
                return None
        if any(math.hypot(loc.x - px, loc.y - py) < 3.0 for px, py in self.server.blocked):
            return None
        v = Vehicle(self.server, bp, transform)
        self.server.actors[v.id] = v
        return v

    def spawn_actor(self, bp, transform, attach_to=None):
        self.server.call(f"spawn {bp.id}")
        a = Sensor(self.server, bp, transform, attach_to)
        self.server.actors[a.id] = a
        return a

    def tick(self, seconds: float = 10.0) -> int:
        self.server.call("tick")
        return self.server.advance()


class FakeServer:
    """The simulated server behind one address."""

    def __init__(self, address: str = "localhost:2000", version: str = "0.9.16", town: str = "Town07"):
        self.address, self.version = address, version
        self.map = Map()
        self.map.name = f"Carla/Maps/{town}"
        self.settings = WorldSettings(False, False, None)
        self.actors: dict[int, Actor] = {}
        self.log: list[str] = []
        self.frame, self.next_id = 100, 0
        self.posts: list[tuple[float, float, float]] = [(25.0, 4.0, 0.5)]  # (x, y, radius): 4 m right of lane 0
        self.blocked: list[tuple[float, float]] = []
        self.dead = self.lidar_silent = False
        self.rogue_ticks = 0
        self.loaded: list[str] = []

    def call(self, what: str) -> None:
        if self.dead:
            raise RuntimeError(TIMEOUT_TEXT.format(ms=10000, addr=self.address))
        self.log.append(what)

    def advance(self) -> int:
        self.frame += 1 + self.rogue_ticks
        dt = self.settings.fixed_delta_seconds or 0.05
        for v in [a for a in self.actors.values() if isinstance(a, Vehicle)]:
            v.physics(dt)
        for s in [a for a in self.actors.values() if isinstance(a, Sensor)]:
            if s.callback is None or s.parent is None:
                continue
            if s.type_id == "sensor.lidar.ray_cast" and not self.lidar_silent:
                s.callback(LidarMeasurement(self.frame, self._scan(s.parent)))
            if s.type_id == "sensor.other.collision":
                if any(math.hypot(s.parent.x - px, s.parent.y - py) < r + 1.0 for px, py, r in self.posts):
                    s.callback(CollisionEvent(self.frame))
        return self.frame

    def _scan(self, v: Vehicle) -> bytes:
        r = math.radians(v.yaw)
        pts = [(0.3, 0.2, 0.0, 1.0)]  # a ray that hits the ego's own body: the env must drop it
        for px, py, rad in self.posts:
            dx, dy = px - v.x, py - v.y
            lx, ly = dx * math.cos(r) + dy * math.sin(r), -dx * math.sin(r) + dy * math.cos(r)  # sensor frame
            d = math.hypot(lx, ly)
            if 0 < d - rad <= 20.0:
                pts.append((lx * (d - rad) / d, ly * (d - rad) / d, 0.0, 0.9))
        return np.array(pts, dtype=np.float32).tobytes()  # (N, 4) float32

    def sensors(self) -> list[Sensor]:
        return [a for a in self.actors.values() if isinstance(a, Sensor)]


SERVERS: dict[str, FakeServer] = {}  # address -> server ("no server" when absent)


class Client:
    def __init__(self, host: str = "127.0.0.1", port: int = 2000, worker_threads: int = 0):
        self.address, self.timeout = f"{host}:{port}", 5.0

    def _server(self) -> FakeServer:
        server = SERVERS.get(self.address)
        if server is None:
            raise RuntimeError(TIMEOUT_TEXT.format(ms=int(self.timeout * 1000), addr=self.address))
        return server

    def set_timeout(self, seconds: float) -> None:
        self.timeout = seconds

    def get_client_version(self) -> str:
        return "0.9.16"

    def get_server_version(self) -> str:
        server = self._server()
        server.call("get_server_version")
        return server.version

    def get_world(self) -> World:
        server = self._server()
        server.call("get_world")
        return World(server)

    def load_world(self, town: str, reset_settings: bool = True) -> World:
        server = self._server()
        server.call(f"load_world {town}")
        server.map = Map()
        server.map.name = f"Carla/Maps/{town}"
        server.loaded.append(town)
        server.actors.clear()
        return World(server)


def module() -> types.ModuleType:
    """A stand-in ``carla`` module (put it in ``sys.modules["carla"]``)."""
    m = types.ModuleType("carla")
    m.__doc__ = "TEST DOUBLE of the carla client (tests/envs/carla_double.py)"
    for obj in (Client, Location, Rotation, Transform, Vector3D, VehicleControl, WorldSettings):
        setattr(m, obj.__name__, obj)
    return m
