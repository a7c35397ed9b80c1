"""Front crawl (freestyle) swimming, prone, with a six-beat flutter kick.

The body lies face down along +X at a fixed height above the floor (the water surface is not
modelled) and rolls about its long axis by about 35 degrees with each stroke (Psycharakis &
Sanders 2010, J. Sports Sci. 28(4)); each arm circles the shoulder, pulling under the body and
recovering above it with the elbow bent; the legs flutter three times per arm cycle each, out
of phase; the head turns to breathe every cycle on the right. A stroke cycle takes about
1.8 s at tempo 1 and the swimmer moves at about 1 m/s.
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models.generator.ik import axis_rotation
from avatarsim.avatar_models.generator.plan import LimbTarget, Plan, Scene, realise
from avatarsim.avatar_models.generator.poses import X_AXIS, Y_AXIS

TAU = 2.0 * np.pi


def swim(scene: Scene) -> Plan:
    n, t, height = scene.n_frames, scene.times, scene.subject.height_m
    style = scene.style
    amp = min(style.amplitude, 1.15)
    frequency = 0.55 * style.tempo
    cycle = frequency * t
    roll = np.radians(35.0) * amp * np.sin(TAU * cycle)
    prone = axis_rotation(Y_AXIS, np.full(n, np.pi / 2))
    root_rot = axis_rotation(X_AXIS, roll) @ prone
    speed = 1.0 * style.tempo * np.sqrt(amp)
    root = np.column_stack([speed * (t - t[0]), np.zeros(n), np.full(n, 0.5 * height)])
    joints = {}
    for side in ("L", "R"):
        # Six-beat kick: three kicks per leg per stroke cycle, legs in antiphase.
        kick = np.sin(TAU * 3.0 * cycle + (0.0 if side == "L" else np.pi))
        joints[f"Bip01 {side} Thigh"] = axis_rotation(
            Y_AXIS, -np.radians(14.0) * amp * kick - np.radians(5.0)
        )
        joints[f"Bip01 {side} Calf"] = axis_rotation(
            Y_AXIS, np.radians(18.0) * (1 + kick) / 2 + np.radians(5.0)
        )
        joints[f"Bip01 {side} Foot"] = axis_rotation(Y_AXIS, np.full(n, np.radians(45.0)))
    # Face down looking slightly ahead; turn with half the body roll, and fully to the right
    # for a breath once per cycle.
    breath = 1.2 * np.exp(-((((cycle % 1.0) - 0.72) / 0.12) ** 2))
    head = axis_rotation(X_AXIS, 0.5 * roll - breath) @ axis_rotation(
        Y_AXIS, np.full(n, np.pi / 2 - 0.35)
    )
    plan = Plan(
        root_pos=root,
        root_rot=root_rot,
        pelvis=scene.constant(np.eye(3)),
        spine=scene.constant(np.eye(3)),
        head=head,
        contacts=np.zeros((n, 2), bool),
        joints=joints,
        fist=np.full((n, 2), 0.1),
    )
    shoulders = realise(scene, plan).global_positions()
    for side, offset in (("L", 0.0), ("R", 0.5)):
        u = (cycle + offset) % 1.0
        # Faster underwater pull than recovery: warp the phase so the pull takes about 45 %.
        psi = TAU * (u + 0.05 * np.sin(TAU * u))
        reach = sum(np.linalg.norm(scene.offset(f"Bip01 {side} {j}")) for j in ("Forearm", "Hand"))
        hand, pole = _stroke(psi, side)
        shoulder = shoulders[:, scene.skeleton.index(f"Bip01 {side} UpperArm")]
        plan.arms[side] = LimbTarget(
            shoulder + np.einsum("tab,tb->ta", root_rot, reach * hand),
            np.einsum("tab,tb->ta", root_rot, pole),
        )
    return plan


def _stroke(psi: np.ndarray, side: str) -> tuple[np.ndarray, np.ndarray]:
    """Hand position relative to the shoulder (arm lengths) and elbow pole direction, both
    ``(T, 3)`` in the trunk's frame (x ventral, y left, z towards the head), at stroke angle
    ``psi (T,)``: 0 at hand entry ahead of the head, the pull under the body while
    ``sin(psi) > 0``, the recovery above the water while it is negative.

    The hand sweeps in under the body's midline while pulling and exits at the hip; the
    recovery brings it forward out to the side with the elbow high (the humerus rotated
    inwards, elbow pointing to the sky), and the elbow points sideways through the pull (a
    high-elbow catch; Maglischo 2003, *Swimming Fastest*, ch. 5). The hand's loop goes round
    the side, not over the shoulder, so the arm never turns a full circle about one axis.
    """
    sin, cos = np.sin(psi), np.cos(psi)
    hand = np.column_stack([0.35 + 0.2 * sin, 0.25 - 0.4 * sin, 0.85 * cos])
    recovery = (1.0 - sin)[:, None] / 2.0
    pole = (1.0 - recovery) * [-0.3, 1.0, 0.0] + recovery * [-1.0, 0.5, 0.0]
    mirror = np.array([1.0, 1.0 if side == "L" else -1.0, 1.0])
    return hand * mirror, pole * mirror
