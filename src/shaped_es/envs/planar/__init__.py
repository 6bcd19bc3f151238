"""Planar waypoint bodies of the task suite: ``PointVel-v0`` (holonomic point, velocity control),
``PointForce-v0`` (point mass, force control with damping: second order), ``Unicycle-v0`` (differential
drive: forward speed and turn rate), ``Rover-v0`` (the differential drive with inertia: thrust and yaw torque)
and ``Kart-v0`` (a car driven by acceleration and steering rate).

They share one task (``task.py``): a random start and goal per episode, spatial waypoints every
``waypoint_spacing`` on the start-goal line (consumed when reached or passed), a dense progress reward,
and one batched NumPy core (``core.py``) whose body (``pointvel.py``, ``pointforce.py``, ``unicycle.py``,
``rover.py``, ``kart.py``) supplies only its dynamics, its observation and its waypoint controller, from
the parts the bodies with a heading or a first-order lag share (``heading.py``); ``env.py`` holds the
Gymnasium side they share (the env base, ``make_config`` over a body's presets, the registered entry points).
"""
