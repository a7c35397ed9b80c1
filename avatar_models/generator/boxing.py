"""Shadow boxing in an orthodox stance: guard, jab, lead hook and rear uppercut.

The boxer stands bladed (left foot forward, body turned about 20 degrees to the right) with
bent knees and a small bounce. A seeded sequence alternates guard holds with punches; each
punch is a few keyframed poses of both hand targets, trunk twist and knee dip, eased with
minimum-jerk segments and solved by two-bone IK. Poses are for a 1.75 m boxer facing +X and
scale with stature; punch durations (0.4-0.7 s) follow amateur boxing timing (Whiting,
Gregor & Finerman 1988, Med. Sci. Sports Exerc. 20(2)).
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models.generator.curves import keyframes
from avatarsim.avatar_models.generator.feet import FootGeometry, planted
from avatarsim.avatar_models.generator.ik import axis_rotation
from avatarsim.avatar_models.generator.plan import LimbTarget, Plan, Scene
from avatarsim.avatar_models.generator.poses import Y_AXIS, gaze, heading_rotation, trunk

STANCE_YAW = np.radians(-20.0)


def _pose(
    left, right, twist=0.0, dip=0.0, left_pole=(-0.3, 0.6, -1.0), right_pole=(-0.3, -0.6, -1.0)
):
    """A keyframe vector: hand targets (x from the root, y, z; metres at 1.75 m), trunk twist
    (radians, left turn positive), knee dip (metres), elbow pole directions."""
    return np.array([*left, *right, twist, dip, *left_pole, *right_pole], dtype=float)


# Jab and hook end with the palm down and the elbow turned up and out (the hook swings with
# the elbow at shoulder height): that pole keeps the humerus within its internal rotation
# range (70 deg, AAOS); an elbow pointing down would need about 150.
ELBOW_OUT = (0.0, 1.0, 1.0)
GUARD = _pose((0.30, 0.10, 1.45), (0.20, -0.10, 1.47))
# Each punch: (duration at tempo 1 in seconds, key fractions, key poses) from guard to guard.
PUNCHES = {
    "jab": (
        0.45,
        (0.0, 0.35, 0.5, 1.0),
        (
            GUARD,
            _pose((0.70, 0.04, 1.42), (0.20, -0.10, 1.47), -0.15, 0.0, ELBOW_OUT),
            _pose((0.70, 0.04, 1.42), (0.20, -0.10, 1.47), -0.15, 0.0, ELBOW_OUT),
            GUARD,
        ),
    ),
    # The rear hand guards the chin, which the hook's trunk turn carries to the right: a hand
    # held at the guard's place would pull the rear arm across the chest, rotated inwards past
    # its range.
    "hook": (
        0.65,
        (0.0, 0.3, 0.55, 0.7, 1.0),
        (
            GUARD,
            _pose((0.25, 0.32, 1.40), (0.20, -0.10, 1.47), 0.15, 0.02, ELBOW_OUT),
            _pose((0.45, -0.02, 1.45), (0.12, -0.22, 1.45), -0.5, 0.02, ELBOW_OUT),
            _pose((0.45, -0.02, 1.45), (0.12, -0.22, 1.45), -0.5, 0.02, ELBOW_OUT),
            GUARD,
        ),
    ),
    "uppercut": (
        0.65,
        (0.0, 0.3, 0.55, 0.7, 1.0),
        (
            GUARD,
            _pose((0.30, 0.10, 1.45), (0.25, -0.15, 1.15), 0.1, 0.06),
            _pose(
                (0.30, 0.12, 1.45), (0.45, -0.02, 1.55), 0.45, -0.02, right_pole=(0.0, -0.5, -1.0)
            ),
            _pose(
                (0.30, 0.12, 1.45), (0.45, -0.02, 1.55), 0.45, -0.02, right_pole=(0.0, -0.5, -1.0)
            ),
            GUARD,
        ),
    ),
}


def _timeline(scene: Scene, span: float) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Key times ``(K,)``, key poses ``(K, 14)`` and the punch names of a seeded sequence:
    guard holds between punches, every punch kind once per round in a random order."""
    rng, tempo = scene.rng, scene.style.tempo
    times, poses, names = [0.0], [GUARD], []
    while times[-1] < span:
        hold = rng.uniform(0.3, 0.6) / tempo
        times.append(times[-1] + hold)
        poses.append(GUARD)
        for name in rng.permutation(list(PUNCHES)):
            duration, fractions, keys = PUNCHES[str(name)]
            start = times[-1]
            times.extend(start + np.asarray(fractions[1:]) * duration / tempo)
            poses.extend(keys[1:])
            names.append(str(name))
            times.append(times[-1] + rng.uniform(0.15, 0.4) / tempo)
            poses.append(GUARD)
    return np.array(times), np.array(poses), names


def box(scene: Scene) -> Plan:
    n, t, height = scene.n_frames, scene.times - scene.times[0], scene.subject.height_m
    scale = height / 1.75
    key_t, key_p, names = _timeline(scene, t[-1])
    pose = keyframes(t, key_t, key_p)
    amplitude = scene.style.amplitude
    # Hand reach scales with the body and, around the guard, with the style's amplitude.
    left = GUARD[:3] + (pose[:, 0:3] - GUARD[:3]) * min(amplitude, 1.1)
    right = GUARD[3:6] + (pose[:, 3:6] - GUARD[3:6]) * min(amplitude, 1.1)
    geom = FootGeometry.of(scene)
    ankle_z = -geom.heel[2]
    feet = {
        "L": planted(geom, np.broadcast_to([0.12 * height, 0.07 * height, ankle_z], (n, 3))),
        "R": planted(geom, np.broadcast_to([-0.13 * height, -0.09 * height, ankle_z], (n, 3))),
    }
    bounce = 0.012 * height * amplitude * (1 - np.cos(2 * np.pi * 1.8 * scene.style.tempo * t)) / 2
    root_z = scene.skeleton.offsets[0, 2] - (0.07 + scene.style.knee_bend) * scene.leg_length
    root_pos = np.column_stack(
        [np.zeros(n), np.full(n, -0.01 * height), root_z - bounce - pose[:, 7] * scale]
    )
    # Hands follow the crouch and bounce of the body, and lean with a stooping style's trunk
    # (about the pelvis): the guard is held in front of the chest, not at a fixed height.
    root_rot = heading_rotation(STANCE_YAW, n)
    lean = root_rot[0] @ axis_rotation(Y_AXIS, [np.radians(scene.style.stoop_deg)])[0]
    lean = lean @ root_rot[0].T
    rest_root = scene.skeleton.offsets[0]

    def hand_target(rel: np.ndarray) -> np.ndarray:
        return root_pos + (rel * scale - rest_root) @ lean.T

    plan = Plan(
        root_pos=root_pos,
        root_rot=root_rot,
        pelvis=scene.constant(np.eye(3)),
        spine=trunk(scene, np.radians(8.0), np.radians(12.0) + pose[:, 6]),
        head=gaze(scene, 0.0, np.radians(10.0)),
        contacts=np.ones((n, 2), bool),
        legs={
            side: LimbTarget(ft.ankle, np.broadcast_to([1.0, 0.3 * sg, 0.0], (n, 3)), ft.rotation)
            for (side, ft), sg in zip(feet.items(), (1, -1), strict=True)
        },
        arms={
            "L": LimbTarget(hand_target(left), pose[:, 8:11]),
            "R": LimbTarget(hand_target(right), pose[:, 11:14]),
        },
        fist=np.ones((n, 2)),
        meta={"punches": names},
    )
    return plan
