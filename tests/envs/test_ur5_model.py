"""UR5 model: MuJoCo kinematics vs the published DH parameters; model settings; Bezier waypoints."""

import mujoco
import numpy as np
import pytest

from shaped_es.envs.ur5.bezier import bezier_point, bezier_waypoints
from shaped_es.envs.ur5.config import PRESETS, make_config
from shaped_es.envs.ur5.core import JOINTS, UR5Core
from shaped_es.envs.ur5.kinematics import fk_position, world_jacobian, world_position


@pytest.fixture(scope="module")
def core():
    return UR5Core(make_config())


def test_dh_zero_pose_is_the_published_ur5_value():
    # q = 0: x = a2 + a3, y = -(d4 + d6), z = d1 - d5 (UR5 DH table)
    np.testing.assert_allclose(fk_position(np.zeros(6)), [-0.81725, -0.19145, 0.089159 - 0.09465], atol=1e-12)


def test_mujoco_site_matches_dh_kinematics_at_random_configurations(core):
    q = np.random.default_rng(0).uniform(-2 * np.pi, 2 * np.pi, (300, 5))  # (300, 5)
    err = np.linalg.norm(core.end_effector(q) - world_position(q), axis=1)
    assert err.max() < 1e-3  # within 1 mm (in fact ~1e-15: the bodies sit on the DH frames)


def test_dh_jacobian_matches_finite_differences():
    q = np.random.default_rng(1).uniform(-3, 3, (5, 5))
    eps = 1e-6
    num = np.stack([(world_position(q + eps * np.eye(5)[j]) - world_position(q)) / eps for j in range(5)], -1)
    np.testing.assert_allclose(world_jacobian(q), num, atol=1e-5)


def test_model_has_five_actuated_joints_with_ur5_limits_and_config_physics():
    cfg = make_config(torque_limits=(100, 90, 80, 20, 10), joint_damping=(1, 2, 3, 4, 5), timestep=0.005)
    m = UR5Core(cfg).model
    assert (m.nq, m.nv, m.nu) == (5, 5, 5)  # wrist 3 fixed
    assert [m.joint(j).name for j in range(m.njnt)] == list(JOINTS)
    np.testing.assert_allclose(m.jnt_range, np.tile([-2 * np.pi, 2 * np.pi], (5, 1)), atol=1e-6)
    np.testing.assert_allclose(m.actuator_gear[:, 0], cfg.torque_limits)
    np.testing.assert_allclose(m.actuator_ctrlrange, np.tile([-1, 1], (5, 1)))
    np.testing.assert_allclose(m.dof_damping, cfg.joint_damping)
    assert m.opt.timestep == 0.005
    assert (m.body_gravcomp[2:] == 1.0).all()  # every moving link gravity compensated
    assert m.geom("ground").type == 0  # mjGEOM_PLANE


def test_home_pose_is_collision_free_and_matches_documented_start(core):
    data = mujoco.MjData(core.model)
    data.qpos[:] = core.config.start_qpos
    mujoco.mj_forward(core.model, data)
    assert data.ncon == 0
    np.testing.assert_allclose(core.end_effector(np.array([core.config.start_qpos]))[0],
                               [-0.10915, 0.4869, 0.431859], atol=1e-6)


def test_bezier_waypoints_start_at_start_and_end_at_target():
    rng = np.random.default_rng(2)
    p0, p2, p1 = rng.normal(size=(4, 3)), rng.normal(size=(4, 3)), np.array([0.75, 0.15, 0.45])
    w = bezier_waypoints(p0, p1, p2, 100)  # (4, 100, 3)
    assert w.shape == (4, 100, 3)
    np.testing.assert_allclose(w[:, 0], p0)
    np.testing.assert_allclose(w[:, -1], p2)
    np.testing.assert_allclose(bezier_point(p0, p1, p2, np.full(4, 0.5)), 0.25 * p0 + 0.5 * p1 + 0.25 * p2)


def test_core_waypoints_run_from_start_effector_to_target(core):
    state, _, info = core.reset(np.arange(5))
    np.testing.assert_allclose(info["waypoint"], info["position"])  # waypoint 0 = P0 = start effector
    last = type(state)(**{**state.__dict__, "index": np.full(5, core.config.num_waypoints - 1)})
    np.testing.assert_allclose(core.waypoint(last), state.target)


def test_targets_lie_in_the_configured_upper_hemisphere_shell():
    for preset in ("default", "paper"):
        cfg = PRESETS[preset]
        _, _, info = UR5Core(cfg).reset(np.arange(400))
        t = info["target"]
        r = np.linalg.norm(t, axis=1)
        assert (r >= cfg.target_radius[0] - 1e-9).all() and (r <= cfg.target_radius[1] + 1e-9).all()
        el = np.arcsin(t[:, 2] / r)
        assert (el >= cfg.target_elevation[0] - 1e-9).all() and (el <= cfg.target_elevation[1] + 1e-9).all()
        az = np.arctan2(t[:, 1], t[:, 0])
        assert (az >= cfg.target_azimuth[0] - 1e-9).all() and (az <= cfg.target_azimuth[1] + 1e-9).all()
    assert (np.abs(az) > np.pi / 2).any()  # paper: the whole hemisphere, behind the base too


def test_config_errors_are_one_line():
    for kwargs in ({"nope": 1}, {"reach_radius": -1.0}, {"torque_limits": (1, 2)}):
        with pytest.raises(ValueError) as err:
            make_config(**kwargs)
        assert "\n" not in str(err.value) and "UR5Reach-v0" in str(err.value)
    with pytest.raises(ValueError):
        make_config("nonexistent")
    assert make_config(target_radius=[0.3, 0.5]).target_radius == (0.3, 0.5)  # YAML lists -> tuples
