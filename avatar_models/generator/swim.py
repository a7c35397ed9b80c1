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

from avatar_models.generator.ik import axis_rotation
from avatar_models.generator.plan import Plan, Scene, sided
from avatar_models.generator.poses import X_AXIS, Y_AXIS, Z_AXIS

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
    for side, offset in (("L", 0.0), ("R", 0.5)):
        u = (cycle + offset) % 1.0
        # Faster underwater pull than recovery: warp the phase so the pull takes about 45 %.
        psi = TAU * (u + 0.05 * np.sin(TAU * u))
        upper = axis_rotation(Y_AXIS, psi) @ axis_rotation(X_AXIS, np.full(n, np.pi / 2))
        # Elbow: a moderate bend through the pull (high-elbow catch), a strong one in recovery.
        elbow = np.where(np.sin(psi) > 0, 0.6 * np.sin(psi), -1.5 * np.sin(psi))
        joints[f"Bip01 {side} UpperArm"] = sided(upper, side)
        joints[f"Bip01 {side} Forearm"] = sided(axis_rotation(Z_AXIS, -elbow), side)
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
    return Plan(
        root_pos=root,
        root_rot=root_rot,
        pelvis=scene.constant(np.eye(3)),
        spine=scene.constant(np.eye(3)),
        head=head,
        contacts=np.zeros((n, 2), bool),
        joints=joints,
        fist=np.full((n, 2), 0.1),
    )
