"""Individual checks against analytic cases: residual force, friction cone, config, skating."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.config import ConfigError
from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.motion import Motion
from avatarsim.sim.checks.joint_limits import JointLimitCheck
from avatarsim.sim.checks.replay import BodyReplay
from avatarsim.sim.checks.residual import cone_distance
from avatarsim.sim.checks.skating import contact_runs, slip_velocity
from avatarsim.sim.plausibility import check_motion
from avatarsim.sim.thresholds import CheckConfig


@pytest.fixture(scope="module")
def rest_body():
    skeleton = generate("balance", duration_s=0.1).skeleton
    return build_body(skeleton)


def still_pose(body, height_above_rest: float, frames: int = 60) -> Motion:
    """The rest pose, standing on the floor (``height_above_rest=0``) or held above it."""
    rot = np.zeros((frames, body.skeleton.n_joints, 4))
    rot[..., 0] = 1.0
    root = np.zeros((frames, 3))
    root[:, 2] = body.root_height + height_above_rest
    return Motion(body.skeleton, 60.0, root, rot)


def test_residual_force_zero_standing_one_body_weight_in_the_air(rest_body):
    standing = check_motion(still_pose(rest_body, 0.0), rest_body)
    hanging = check_motion(still_pose(rest_body, 0.5), rest_body)
    assert standing.values["residual_force_bw_p95"] < 0.01
    np.testing.assert_allclose(hanging.values["residual_force_bw_p95"], 1.0, atol=0.02)
    assert standing.passed and hanging.flagged("residual_force")


def test_standing_pose_touches_floor_without_penetrating(rest_body):
    r = check_motion(still_pose(rest_body, 0.0), rest_body)
    assert r.values["penetration_cm_p95"] < 0.1
    assert r.values["contact_frac"] == 1.0 and r.values["skate_cm_s_median"] < 1e-6
    assert r.values["com_outside_support_frac"] == 0.0  # CoM between the feet


def test_ballistic_flight_needs_no_residual_force(rest_body):
    """A body in free fall (root following -g/2 t^2, high above the floor) needs no force."""
    m = still_pose(rest_body, 1.0, frames=90)
    t = m.times
    root = m.root_pos.copy()
    root[:, 2] += 2.0 * t - 0.5 * 9.81 * t**2
    r = check_motion(m.replace(root_pos=root), rest_body)
    assert np.percentile(r.per_frame()["residual_force_bw"][5:-5], 95) < 0.02


def test_cone_distance_analytic():
    f = np.array([[0, 0, 1.0], [2.0, 0, 1.0], [0, 0, -1.0], [1.0, 0, 0.0]])
    np.testing.assert_allclose(cone_distance(f, 1.0), [0.0, 1 / np.sqrt(2), 1.0, 1 / np.sqrt(2)])


def test_contact_runs():
    runs = contact_runs(np.array([0, 1, 1, 0, 1, 0, 1, 1, 1], dtype=bool))
    np.testing.assert_array_equal(runs, [[1, 2], [4, 4], [6, 8]])


def test_slip_velocity_of_a_rigid_sole_is_zero_at_its_pivot():
    """Heel (0, 0) and toe (0.25, 0) turning about (0.1, 0): the pivot between them does not
    slip; translated, every point slips; turning about a point behind the heel, the heel
    (the stillest point of the sole) slips."""
    omega = 2.0
    pts = np.array([[0.0, 0.0], [0.25, 0.0]])
    turn = omega * np.stack([-(pts[:, 1] - 0.0), pts[:, 0] - 0.1], axis=-1)  # w x (p - c)
    both = np.ones(2, dtype=bool)
    np.testing.assert_allclose(slip_velocity(turn, both), [0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(slip_velocity(np.tile([0.0, 0.3], (2, 1)), both), [0.0, 0.3])
    np.testing.assert_allclose(slip_velocity(turn + [0.0, 0.3], both), [0.0, 0.1], atol=1e-12)
    # the heel alone in contact slips at its own velocity; no contact: NaN
    np.testing.assert_allclose(slip_velocity(turn, np.array([True, False])), turn[0])
    assert np.all(np.isnan(slip_velocity(turn, np.zeros(2, dtype=bool))))


def pivot_on_left_sole(body, yaw_deg: float, slide_m: float = 0.0, frames: int = 90) -> Motion:
    """Standing on the left foot (right knee bent, that foot in the air), the whole body turns
    ``yaw_deg`` about a vertical axis through the middle of the left sole (between its heel
    and ball, on none of the sole points the checks sample), and drifts ``slide_m`` along +Y."""
    m = still_pose(body, 0.0, frames)
    knee = body.anatomy.body17["r_knee"]
    order = body.hinge_order(knee)
    ranges = body.hinge_ranges[knee]
    axis = max(ranges, key=lambda a: ranges[a][1] - ranges[a][0])
    angles = np.zeros((frames, 3))
    angles[:, order.lower().index(axis)] = 0.8 * ranges[axis][1]
    local = m.local_rot.copy()
    local[:, knee] = quat.from_scipy(Rotation.from_euler(order, angles))
    m = m.replace(local_rot=local)
    model = body.model
    replay = BodyReplay.run(body, model, body.qpos_from_motion(m[:1]), m.fps, CheckConfig())
    heel, ball = replay.sole_points[0, 0, 0], replay.sole_points[0, 0, 1]
    centre = np.array([*(0.5 * (heel + ball))[:2], 0.0])
    s = np.linspace(0.0, 1.0, frames)
    ramp = s * s * (3.0 - 2.0 * s)  # starts and stops at rest
    turn = Rotation.from_euler("z", np.radians(yaw_deg) * ramp[:, None])
    root = centre + turn.apply(m.root_pos - centre)
    root[:, 1] += slide_m * ramp
    local[:, 0] = quat.mul(quat.from_scipy(turn), local[:, 0])
    return m.replace(root_pos=root, local_rot=local)


def test_pivot_about_the_sole_is_no_skating_but_sliding_is(rest_body):
    """A basketball pivot: the planted foot turns 60 degrees about a point of its sole. The
    heel and toe travel ~10 cm each, the foot's contact does not move: not skating. A drift
    of 20 cm is skating, with the pivot too (part of it is then a turn about a point further
    back on the sole)."""
    pivot = check_motion(pivot_on_left_sole(rest_body, 60.0), rest_body)
    assert pivot.values["contact_frac"] == 1.0
    assert pivot.values["skate_slide_cm_max"] < 1.0, pivot.values
    assert pivot.values["skate_cm_s_median"] < 1.0 and not pivot.flagged("skating")
    sliding = check_motion(pivot_on_left_sole(rest_body, 0.0, slide_m=0.20), rest_body)
    np.testing.assert_allclose(sliding.values["skate_slide_cm_max"], 20.0, atol=0.5)
    both = check_motion(pivot_on_left_sole(rest_body, 60.0, slide_m=0.20), rest_body)
    assert sliding.flagged("skating") and both.flagged("skating")


def test_config_from_dict_and_toml(tmp_path):
    assert CheckConfig.from_dict({"penetration_cm_p95": 2}).penetration_cm_p95 == 2.0
    with pytest.raises(ConfigError, match="unknown"):
        CheckConfig.from_dict({"no_such_key": 1.0})
    with pytest.raises(ConfigError, match="friction must be > 0 and <= 10, got -1"):
        CheckConfig.from_dict({"friction": -1.0})
    path = tmp_path / "c.toml"
    path.write_text("[checks]\ncontact_height_m = 0.03\n")
    assert CheckConfig.from_toml(path).contact_height_m == 0.03


def test_support_margin_matches_scipy_convex_hull():
    from scipy.spatial import ConvexHull

    from avatarsim.sim.checks.support import outside_margin

    rng = np.random.default_rng(3)
    points = rng.uniform(-0.2, 0.2, size=(200, 8, 2))
    active = rng.random((200, 8)) < 0.8
    active[:, :3] = True
    com = rng.uniform(-0.4, 0.4, size=(200, 2))
    expected = []
    for t in range(200):
        eq = ConvexHull(points[t, active[t]]).equations
        expected.append(max(0.0, np.max(eq[:, :2] @ com[t] + eq[:, 2])))
    np.testing.assert_allclose(outside_margin(points, active, com), expected, atol=1e-9)


def test_support_margin_is_translation_invariant_and_nan_without_support():
    from avatarsim.sim.checks.support import outside_margin

    rng = np.random.default_rng(4)
    points = rng.uniform(-0.2, 0.2, size=(50, 16, 2))
    active = rng.random((50, 16)) < 0.7
    active[:, :3] = True
    active[7] = False  # no support in frame 7
    com = rng.uniform(-0.4, 0.4, size=(50, 2))
    near = outside_margin(points, active, com)
    far = np.array([80.0, -40.0])  # a minute of walking away from the origin
    np.testing.assert_allclose(outside_margin(points + far, active, com + far), near, atol=1e-9)
    assert np.isnan(near[7]) and np.isfinite(np.delete(near, 7)).all()


def _joint_limits(body, bends_deg: dict[str, tuple[float, str]]):
    """The joint-limit check of the rest pose with joints bent ``{joint: (degrees, axis)}``."""
    m = still_pose(body, 0.0, frames=4)
    rot = m.local_rot.copy()
    for name, (deg, axis) in bends_deg.items():
        rot[:, body.skeleton.index(name)] = quat.from_scipy(
            Rotation.from_euler(axis, deg, degrees=True)
        )
    m = m.replace(local_rot=rot)
    model = body.model
    replay = BodyReplay.run(body, model, body.qpos_from_motion(m), m.fps, CheckConfig())
    return JointLimitCheck()(replay, CheckConfig())


def test_neck_chain_is_judged_by_its_total_not_by_each_joints_share(rest_body):
    """The avatar's neck (Bip01 Neck, Bip01 Head) shares the cervical range, flexion 45: one
    joint bent 60 against the other's -25 (35 in all, as CMU's neck joints bend against
    each other) passes; both bent 45 (90 in all) fails as the chain, by 45 degrees, though
    each is within the range alone."""
    neck, head = "Bip01 Neck", "Bip01 Head"
    opposite = _joint_limits(rest_body, {neck: (-25.0, "y"), head: (60.0, "y")})
    assert opposite.values["joint_limit_violation_frac"] == 0.0
    assert opposite.values["limit_excess_deg_max"] == pytest.approx(15.0)  # head: 60 vs 45
    too_far = _joint_limits(rest_body, {neck: (45.0, "y"), head: (45.0, "y")})
    assert too_far.values["joint_limit_violation_frac"] == 1.0
    ((name, v),) = too_far.details["violations"].items()
    assert name == f"{neck}+{head}:ry"
    assert v["max_deg"] == pytest.approx(45.0) and v["angles_deg_at_max"] == pytest.approx([45, 45])
    # Lateral bending (about x) of the spine chain (35 in all): 3 x 20 = 60 is 25 beyond.
    spine = {f"Bip01 Spine{s}": (20.0, "x") for s in ("", "1", "2")}
    side = _joint_limits(rest_body, spine).details["violations"]
    assert list(side) == ["Bip01 Spine+Bip01 Spine1+Bip01 Spine2:rx"]
    assert side["Bip01 Spine+Bip01 Spine1+Bip01 Spine2:rx"]["max_deg"] == pytest.approx(25.0)


def test_single_joint_keeps_its_own_limit(rest_body):
    """A joint alone on its role (the knee) is judged by its own range: flexion 135 + 30."""
    r = _joint_limits(rest_body, {"Bip01 L Calf": (165.0, "y")})
    assert list(r.details["violations"]) == ["Bip01 L Calf:ry"]
    assert r.details["violations"]["Bip01 L Calf:ry"]["max_deg"] == pytest.approx(30.0)


def crossed_forearms(body, frames: int = 10) -> Motion:
    """The rest pose (a T-pose) with both upper arms turned 85 degrees forward and both
    elbows bent 95 degrees inward: each forearm points straight at the other shoulder (85 +
    95 = 180), and both lie on one line in front of the chest at shoulder height, so the
    forearms and hands pass through each other, which no body can do. (85 rather than 90
    keeps the shoulder's Euler decomposition out of gimbal lock.)"""
    m = still_pose(body, 0.0, frames)
    rot = m.local_rot.copy()
    sk = body.skeleton
    for side, sign in (("L", -1.0), ("R", 1.0)):  # left arm: rest +Y, forward is -Z turn
        for joint, deg in (("UpperArm", 85.0), ("Forearm", 95.0)):
            turn = Rotation.from_euler("z", sign * deg, degrees=True)
            rot[:, sk.index(f"Bip01 {side} {joint}")] = quat.from_scipy(turn)
    return m.replace(local_rot=rot)


def test_self_collision_flags_forearms_through_each_other_not_the_rest_pose(rest_body):
    """Two coaxial capsules of radius r overlap by 2 r: the check must report that depth
    (the forearm capsules' radius from the model, not a check constant) and flag every
    frame; the rest pose has no self-contact at all."""
    rest = check_motion(still_pose(rest_body, 0.0, 10), rest_body)
    assert rest.values["self_collision_frac"] == 0.0
    assert not rest.per_frame()["self_collision_cm"].any()
    crossed = crossed_forearms(rest_body)
    pos = crossed.global_positions()[0]
    sk = rest_body.skeleton
    l_hand, r_hand = pos[sk.index("Bip01 L Hand")], pos[sk.index("Bip01 R Hand")]
    assert l_hand[1] < 0.0 < r_hand[1]  # each hand is past the midline, on the other side
    assert l_hand[0] > 0.2 and abs(l_hand[2] - r_hand[2]) < 1e-9  # in front, one height
    report = check_motion(crossed, rest_body)
    model = rest_body.model
    forearm = model.body("Bip01 L Forearm").id
    (geom,) = np.flatnonzero(model.geom_bodyid == forearm)
    assert model.geom_type[geom] == mujoco.mjtGeom.mjGEOM_CAPSULE
    depth_cm = report.per_frame()["self_collision_cm"]
    np.testing.assert_allclose(depth_cm, 2 * 100 * model.geom_size[geom, 0], rtol=0.02)
    assert report.values["self_collision_frac"] == 1.0 and report.flagged("self_collision")
    pairs = report.contract()["details"]["self_collision"]["pairs"]
    assert "Bip01 L Forearm / Bip01 R Forearm" in pairs, pairs
