"""Climbing a vertical fixed ladder from the floor, alternating diagonal limbs.

Rungs are 0.305 m apart (12 in, the ANSI A14.3 fixed-ladder spacing). Each foot steps two
rungs at a time (left on even rungs, right on odd ones) and the opposite hand moves with it,
so there are always three points of contact. A swinging limb lifts straight off its rung,
swings back away from the ladder to clear the rung in between, and comes straight down on
the new rung. The pelvis stays a fixed distance behind the ladder and follows the feet.
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models.generator.curves import bump, phase, swing_progress, window
from avatarsim.avatar_models.generator.feet import SWING_LIFT, FootGeometry, FootTrack
from avatarsim.avatar_models.generator.plan import LimbTarget, Plan, Scene
from avatarsim.avatar_models.generator.poses import gaze, heading_rotation, trunk
from avatarsim.avatar_models.generator.standing import leg_targets, reachable_root

RUNG_SPACING_M = 0.305
# Fractions of the climbing cycle: the left foot and right hand move, then the right foot
# and left hand.
LEFT_MOVE = (0.0, 0.38)
RIGHT_MOVE = (0.5, 0.88)


def _stepping(
    local_t: np.ndarray, frequency: float, move: tuple[float, float], first_rung: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rung index before and after the current move ``(T,)`` and swing progress ``tau (T,)``
    of a limb that climbs two rungs per cycle during ``move``, starting on ``first_rung``."""
    cycle, ph = phase(local_t, frequency)
    tau = window(ph, *move)
    start = first_rung + 2 * cycle
    return start, start + 2, tau


def _swing_path(
    base: np.ndarray, z0: np.ndarray, z1: np.ndarray, tau: np.ndarray, back: float, lift: float
) -> np.ndarray:
    """``(T, 3)`` limb path from height ``z0`` to ``z1`` at ``base (3,)`` x/y: straight up off
    the rung, back by ``back`` metres while travelling, straight down onto the new rung."""
    s = swing_progress(tau, SWING_LIFT)
    travel = window(tau, SWING_LIFT, 1.0 - SWING_LIFT)
    x = base[0] - back * bump(travel)
    z = z0 + (z1 - z0) * s + lift * bump(tau)
    return np.column_stack([np.full(tau.shape, x), np.full(tau.shape, base[1]), z])


def climb_ladder(scene: Scene) -> Plan:
    n, height = scene.n_frames, scene.subject.height_m
    scale = height / 1.75
    t = scene.times - scene.times[0]
    frequency = 0.6 * scene.style.tempo
    geom = FootGeometry.of(scene)
    ankle_h = -geom.heel[2]
    ladder_x = 0.45 * scale
    foot_x = ladder_x - geom.ball[0]
    hand_rungs = int(round(0.88 * height / RUNG_SPACING_M))
    feet, arms = {}, {}
    for side, sign, foot_move, foot_first in (("L", 1.0, LEFT_MOVE, 0), ("R", -1.0, RIGHT_MOVE, 1)):
        r0, r1, tau = _stepping(t, frequency, foot_move, foot_first)
        base = np.array([foot_x, sign * 0.09 * scale, 0.0])
        ankle = _swing_path(
            base,
            r0 * RUNG_SPACING_M + ankle_h,
            r1 * RUNG_SPACING_M + ankle_h,
            tau,
            0.22 * scale,
            0.1,
        )
        eye = np.broadcast_to(np.eye(3), (n, 3, 3)).copy()
        feet[side] = FootTrack(ankle, eye, eye.copy(), (tau == 0.0) | (tau == 1.0))
        # The opposite hand moves with this foot, `hand_rungs` above it.
        hand_side = "R" if side == "L" else "L"
        hand_base = np.array([ladder_x - 0.06 * scale, -sign * 0.17 * scale, 0.0])
        hand = _swing_path(
            hand_base,
            (r0 + hand_rungs) * RUNG_SPACING_M,
            (r1 + hand_rungs) * RUNG_SPACING_M,
            tau,
            0.12 * scale,
            0.06,
        )
        # The hand continues the forearm (neutral wrist) and hooks the rung with the fingers:
        # a world "fingers forward, palm down" target bends the wrist past its ranges when
        # the forearm points up along the ladder.
        pole = np.broadcast_to([-0.3, -sign * 1.0, -1.0], (n, 3))
        arms[hand_side] = LimbTarget(hand, pole)
    legs, toes = leg_targets(scene, feet, (1.0, 0.25, 0.0))
    lowest = np.minimum(feet["L"].ankle[:, 2], feet["R"].ankle[:, 2]) - ankle_h
    root = np.column_stack(
        [
            np.full(n, ladder_x - 0.36 * scale),
            np.zeros(n),
            lowest + scene.skeleton.offsets[0, 2] + 0.15 * scale,
        ]
    )
    pelvis = scene.constant(np.eye(3))
    root = reachable_root(scene, root, pelvis, feet)
    top = int(np.ceil(root[:, 2].max() / RUNG_SPACING_M)) + hand_rungs + 2
    return Plan(
        root_pos=root,
        root_rot=heading_rotation(0.0, n),
        pelvis=pelvis,
        spine=trunk(scene, np.radians(6.0)),
        head=gaze(scene, 0.0, np.radians(-20.0)),
        contacts=np.stack([feet[s].contact for s in "LR"], axis=1),
        joints=toes,
        legs=legs,
        arms=arms,
        fist=np.full((n, 2), 0.75),
        meta={
            "ladder_x": float(ladder_x),
            "rung_heights": [RUNG_SPACING_M * k for k in range(1, top + 1)],
        },
    )
