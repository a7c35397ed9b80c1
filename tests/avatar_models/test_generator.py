"""The procedural generator, measured on its output (global joint positions), not its plan."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models.errors import MotionValueError
from avatarsim.avatar_models.generator import (
    ACTIVITIES,
    STYLES,
    Subject,
    generate,
    generate_library,
    sample_subject,
    subject_skeleton,
)

CONTACT_GAP_M = 0.02  # a sole point this close to its support surface touches it
SLIDE_LIMIT_M_S = 0.02
SUBJECTS = (
    [Subject()]
    + [sample_subject(np.random.default_rng(s)) for s in (3, 11)]
    + [
        Subject(height_m=1.52, style="old"),
        Subject(height_m=1.93, style="energetic", leg_factor=1.05),
    ]
)


@pytest.fixture(scope="module")
def clips():
    """Every activity for every subject: ``{(activity, subject index): Motion}``."""
    return {
        (a, i): generate(a, s, duration_s=4.0, fps=90.0, seed=i)
        for a in ACTIVITIES
        for i, s in enumerate(SUBJECTS)
    }


def _sole_points(motion, side: str) -> np.ndarray:
    """``(T, 2, 3)`` heel and toe-tip positions of one foot."""
    sk = motion.skeleton
    return motion.global_positions()[:, sk.indices([f"Bip01 {side} Heel", f"Bip01 {side} Toe0Nub"])]


def _support_gap(motion, side: str, sole_z: np.ndarray) -> np.ndarray:
    """``(T,)`` distance of the lowest sole point to its support: the floor, or a ladder rung
    while the foot's ball is over the rung line."""
    gap = np.abs(sole_z)
    if "rung_heights" in motion.meta:
        ball = motion.global_positions()[:, motion.skeleton.index(f"Bip01 {side} Toe0")]
        at_ladder = np.abs(ball[:, 0] - motion.meta["ladder_x"]) < 0.05
        rungs = np.asarray(motion.meta["rung_heights"])
        rung_gap = np.abs(sole_z[:, None] - rungs[None]).min(axis=1)
        gap = np.where(at_ladder, np.minimum(gap, rung_gap), gap)
    return gap


def foot_slide(motion, side: str) -> tuple[np.ndarray, np.ndarray]:
    """Contact mask ``(T,)`` and horizontal sliding speed ``(T,)`` of one foot.

    The foot touches its support when its lowest sole point is within 2 cm of it. Its sliding
    speed is that of the slowest sole point within 5 mm of the lowest one: a foot rolling
    about its heel or toes does not slide.
    """
    pts = _sole_points(motion, side)
    speed = np.linalg.norm(np.gradient(pts[:, :, :2], 1.0 / motion.fps, axis=0), axis=-1)
    lowest = pts[:, :, 2].min(axis=1)
    support = pts[:, :, 2] < lowest[:, None] + 0.005
    slide = np.where(support, speed, np.inf).min(axis=1)
    return _support_gap(motion, side, lowest) < CONTACT_GAP_M, slide


def test_activity_list_covers_the_required_set():
    required = {"walk", "run", "box", "dribble", "climb_ladder", "swim", "wave", "squat"}
    assert required | {"lunge", "kick", "balance"} <= set(ACTIVITIES)
    assert {"normal", "tired", "happy", "old", "energetic"} <= set(STYLES)


@pytest.mark.parametrize("activity", ACTIVITIES)
def test_feet_in_contact_do_not_slide(clips, activity):
    for i in range(len(SUBJECTS)):
        motion = clips[activity, i]
        contacts = []
        for side in "LR":
            contact, slide = foot_slide(motion, side)
            contacts.append(contact)
            worst = slide[contact].max(initial=0.0)
            assert worst < SLIDE_LIMIT_M_S, f"{activity} subject {i} {side}: {worst:.3f} m/s"
        supported = np.any(contacts, axis=0).mean()
        # The check has something to measure: the body stands on its feet (not in water).
        assert supported == 0.0 if activity == "swim" else supported > 0.5, (activity, i)


@pytest.mark.parametrize("activity", ACTIVITIES)
def test_nothing_goes_through_the_floor_and_bones_keep_their_length(clips, activity):
    for i in range(len(SUBJECTS)):
        motion = clips[activity, i]
        pos = motion.global_positions()
        assert pos[..., 2].min() > -0.01, (activity, i)
        sk = motion.skeleton
        bones = np.linalg.norm(pos[:, 1:] - pos[:, sk.parents[1:]], axis=-1)
        np.testing.assert_allclose(
            bones, np.broadcast_to(sk.bone_lengths[1:], bones.shape), atol=1e-9
        )


def test_subject_height_and_proportions():
    for subject in SUBJECTS:
        z = subject_skeleton(subject).rest_positions()[:, 2]
        assert z.max() - z.min() == pytest.approx(subject.height_m, rel=0.02)
    base = subject_skeleton(Subject(height_m=1.8))
    long_legs = subject_skeleton(Subject(height_m=1.8, leg_factor=1.1))
    thigh = base.index("Bip01 L Calf")
    assert long_legs.bone_lengths[thigh] > 1.03 * base.bone_lengths[thigh]


def test_generated_skeleton_stands_on_the_floor_at_its_rest_offset():
    sk = subject_skeleton(Subject(height_m=1.6, torso_factor=1.05))
    assert (sk.rest_positions() + sk.offsets[0])[:, 2].min() == pytest.approx(0.0, abs=1e-9)


def _speed(motion) -> float:
    return float((motion.root_pos[-1, 0] - motion.root_pos[0, 0]) / motion.duration_s)


def test_walking_and_running_travel_forward_at_human_speeds(clips):
    for i in range(len(SUBJECTS)):
        walk, run = _speed(clips["walk", i]), _speed(clips["run", i])
        assert 0.8 <= walk <= 1.8, (i, walk)
        assert run > 2.0 and run > 1.5 * walk, (i, run)
        # Both feet alternate: each is off the floor for part of every stride.
        for side in "LR":
            contact, _ = foot_slide(clips["walk", i], side)
            assert 0.5 < contact.mean() < 0.85


def test_running_has_a_flight_phase(clips):
    contact = np.stack([foot_slide(clips["run", 0], s)[0] for s in "LR"], axis=1)
    assert (~contact.any(axis=1)).mean() > 0.05


def _joint(motion, name: str) -> np.ndarray:
    return motion.global_positions()[:, motion.skeleton.index(name)]


def test_boxing_hands_reach_forward_and_return_to_guard(clips):
    for i, subject in enumerate(SUBJECTS):
        motion = clips["box", i]
        arm = (
            subject_skeleton(subject)
            .bone_lengths[motion.skeleton.indices(["Bip01 L Forearm", "Bip01 L Hand"])]
            .sum()
        )
        reach = [
            _joint(motion, f"Bip01 {s} Hand")[:, 0] - _joint(motion, f"Bip01 {s} UpperArm")[:, 0]
            for s in "LR"
        ]
        assert max(r.max() for r in reach) > 0.75 * arm
        assert np.median(reach[0]) < 0.6 * arm  # mostly in guard, not punching
        assert set(motion.meta["punches"][:3]) == {"jab", "hook", "uppercut"}


def test_waving_hand_stays_above_the_shoulder(clips):
    for i in range(len(SUBJECTS)):
        motion = clips["wave", i]
        hand, shoulder = _joint(motion, "Bip01 R Hand"), _joint(motion, "Bip01 R UpperArm")
        assert np.all(hand[:, 2] > shoulder[:, 2] + 0.05)
        assert np.ptp(hand[:, 1]) > 0.1  # it actually waves side to side


def test_squat_lowers_the_pelvis(clips):
    for i, subject in enumerate(SUBJECTS):
        z = _joint(clips["squat", i], "Bip01 Pelvis")[:, 2]
        assert z.max() - z.min() > 0.13 * subject.height_m


def test_one_leg_balance_keeps_one_foot_off_the_floor(clips):
    for i in range(len(SUBJECTS)):
        motion = clips["balance", i]
        lowest = np.stack([_sole_points(motion, s)[:, :, 2].min(axis=1) for s in "LR"], axis=1)
        held = motion.times > 1.0
        assert np.all(lowest[held].max(axis=1) > 0.05)
        assert np.all(lowest[held].min(axis=1) < 0.005)


def test_ladder_climber_rises_with_feet_on_rungs(clips):
    motion = clips["climb_ladder", 0]
    assert motion.root_pos[-1, 2] - motion.root_pos[0, 2] > 0.6
    rungs = np.asarray(motion.meta["rung_heights"])
    for side in "LR":
        lowest = _sole_points(motion, side)[:, :, 2].min(axis=1)
        contact, _ = foot_slide(motion, side)
        on_rung = contact & (np.abs(lowest[:, None] - rungs[None]).min(axis=1) < CONTACT_GAP_M)
        assert on_rung.mean() > 0.3


def test_swimmer_is_horizontal_and_moves_forward(clips):
    motion = clips["swim", 0]
    head, pelvis = _joint(motion, "Bip01 Head"), _joint(motion, "Bip01 Pelvis")
    assert np.all(head[:, 0] - pelvis[:, 0] > 0.4)
    assert np.all(np.abs(head[:, 2] - pelvis[:, 2]) < 0.25)
    assert _speed(motion) > 0.5


def test_same_seed_same_bytes_other_seed_differs():
    for activity in ("walk", "box", "balance"):
        a = generate(activity, seed=5, duration_s=1.0)
        b = generate(activity, seed=5, duration_s=1.0)
        c = generate(activity, seed=6, duration_s=1.0)
        assert a.local_rot.tobytes() == b.local_rot.tobytes()
        assert a.root_pos.tobytes() == b.root_pos.tobytes()
        assert not np.array_equal(a.local_rot, c.local_rot)


def test_meta_records_provenance_and_planned_contacts():
    subject = Subject(height_m=1.6, style="tired")
    motion = generate("climb_ladder", subject, duration_s=2.0, fps=30.0, seed=9)
    assert motion.fps == 30.0 and motion.n_frames == 61
    assert motion.meta["activity"] == "climb_ladder" and motion.meta["seed"] == 9
    assert motion.meta["subject"]["height_m"] == 1.6 and motion.meta["subject"]["style"] == "tired"
    contacts = motion.meta["planned_contacts"]
    assert contacts.shape == (61, 2) and contacts.dtype == bool
    assert len(motion.meta["rung_heights"]) > 3


def test_styles_change_the_movement():
    normal = generate("walk", Subject(style="normal"), duration_s=3.0)
    old = generate("walk", Subject(style="old"), duration_s=3.0)
    assert _speed(old) < _speed(normal)
    head_forward = [_joint(m, "Bip01 Head")[:, 0] - m.root_pos[:, 0] for m in (normal, old)]
    assert head_forward[1].mean() > head_forward[0].mean() + 0.03  # stooped


def test_library_covers_activities_and_subjects():
    lib = generate_library(("walk", "wave"), n_subjects=3, duration_s=0.5, fps=30.0, seed=2)
    assert len(lib) == 6
    assert {m.meta["activity"] for m in lib} == {"walk", "wave"}
    assert len({m.meta["subject"]["height_m"] for m in lib}) == 3


def test_bad_requests_raise_typed_errors():
    with pytest.raises(MotionValueError, match="unknown activity"):
        generate("moonwalk")
    with pytest.raises(MotionValueError, match="height"):
        Subject(height_m=2.3)
    with pytest.raises(MotionValueError, match="style"):
        Subject(style="sleepy")
    with pytest.raises(MotionValueError):
        generate("walk", duration_s=0.0)


@pytest.mark.parametrize("activity", ["walk", "run", "lunge", "kick", "climb_ladder", "balance"])
def test_planned_contacts_match_measured_contacts(clips, activity):
    motion = clips[activity, 0]
    measured = np.stack([foot_slide(motion, s)[0] for s in "LR"], axis=1)
    agreement = (measured == motion.meta["planned_contacts"]).mean()
    assert agreement > 0.85, agreement


def test_head_is_stabilised_upright_while_walking_and_running(clips):
    for activity in ("walk", "run"):
        motion = clips[activity, 0]
        head_rot = motion.fk()[1][:, motion.skeleton.index("Bip01 Head")]
        tilt = np.degrees(np.arccos(np.clip(head_rot[:, 2, 2], -1.0, 1.0)))  # head up vs world up
        assert tilt.max() < 20.0, (activity, tilt.max())


def test_boxer_makes_fists(clips):
    motion = clips["box", 0]
    pos, rest = motion.global_positions(), motion.skeleton.rest_positions()
    tip, wrist = motion.skeleton.indices(["Bip01 L Finger2Nub", "Bip01 L Hand"])
    closed = np.linalg.norm(pos[:, tip] - pos[:, wrist], axis=-1)
    assert closed.max() < 0.7 * np.linalg.norm(rest[tip] - rest[wrist])
