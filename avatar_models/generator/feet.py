"""Foot placement: planted feet that roll heel-to-toe, swing arcs, and the pelvis height the
legs can reach.

A foot pose is given by a pivot point that stays fixed on its support (the heel while the foot
rolls down after heel strike, the ball while the heel rises before toe-off) and the foot's
pitch about it, so the part of the sole that touches the support never slides. The toes stay
flat on the support during heel rise (the toe joint bends by minus the pitch).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from avatarsim.avatar_models.generator.curves import bump, phase, smoothstep, swing_progress, window
from avatarsim.avatar_models.generator.ik import axis_rotation
from avatarsim.avatar_models.generator.plan import Scene

Y_AXIS = np.array([0.0, 1.0, 0.0])
# Stance sub-phases of a walking foot as fractions of stance: heel rocker until 0.15, flat
# foot until 0.6, then heel rise (Perry & Burnfield, Gait Analysis, 2nd ed., ch. 4 rockers).
HEEL_ROCKER_END = 0.15
HEEL_RISE_START = 0.6
# Fraction of a swing spent lifting straight up and coming straight down.
SWING_LIFT = 0.12


@dataclass(frozen=True)
class FootGeometry:
    """Heel and ball of the foot relative to the ankle (``Bip01 X Foot``), rest foot frame,
    ``(3,)`` each."""

    heel: np.ndarray
    ball: np.ndarray

    @staticmethod
    def of(scene: Scene) -> FootGeometry:
        return FootGeometry(
            heel=scene.offset("Bip01 L Heel").copy(), ball=scene.offset("Bip01 L Toe0").copy()
        )


@dataclass
class FootTrack:
    """A foot over time: ankle ``(T, 3)``, foot world rotation and toe local rotation
    ``(T, 3, 3)``, and the planned contact ``(T,)`` bool."""

    ankle: np.ndarray
    rotation: np.ndarray
    toe: np.ndarray
    contact: np.ndarray


def foot_pose(
    geom: FootGeometry, pivot: np.ndarray, pitch: np.ndarray, on_ball: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Ankle ``(T, 3)``, foot rotation and toe rotation ``(T, 3, 3)`` of a foot pitched by
    ``pitch (T,)`` (positive: heel up) about ``pivot (T, 3)``: the ball where ``on_ball (T,)``,
    else the heel. The foot faces +X."""
    rot = axis_rotation(Y_AXIS, pitch)
    rel = np.where(on_ball[:, None], geom.ball, geom.heel)
    ankle = pivot - np.einsum("tab,tb->ta", rot, rel)
    toe = axis_rotation(Y_AXIS, np.where(on_ball, -pitch, 0.0))
    return ankle, rot, toe


def planted(geom: FootGeometry, ankle: np.ndarray) -> FootTrack:
    """A foot standing flat with its ankle at ``ankle (T, 3)``."""
    n = ankle.shape[0]
    eye = np.broadcast_to(np.eye(3), (n, 3, 3)).copy()
    return FootTrack(ankle, eye, eye.copy(), np.ones(n, bool))


def swing_between(
    geom: FootGeometry,
    tau: np.ndarray,
    start: np.ndarray,
    end: np.ndarray,
    clearance: float,
    pitch_start: float = 0.0,
    pitch_end: float = 0.0,
    lift: float = SWING_LIFT,
    hang: float = 0.0,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A swing from ball pivot ``start (T, 3)`` pitched ``pitch_start`` to heel pivot
    ``end (T, 3)`` pitched ``pitch_end``, over ``tau (T,)`` in [0, 1]; the ankle is lifted by
    ``clearance * sin(pi tau)`` and travels after a straight lift over the first ``lift`` of
    the swing (:func:`~.curves.swing_progress`); the foot pitches toes-down by a further
    ``hang * sin^2(pi s)`` (``s`` the horizontal progress: smooth, and none while lifting),
    hanging from a knee that flexes in mid-swing. Returns ankle, foot rotation, toe rotation."""
    n = tau.shape[0]
    a0, _, toe0 = foot_pose(geom, start, np.full(n, pitch_start), np.ones(n, bool))
    a1, _, _ = foot_pose(geom, end, np.full(n, pitch_end), np.zeros(n, bool))
    s = swing_progress(tau, lift)
    ankle = a0 + (a1 - a0) * s[:, None]
    ankle[:, 2] += clearance * bump(tau)
    pitch = pitch_start + (pitch_end - pitch_start) * s + hang * bump(s) ** 2
    toe = axis_rotation(Y_AXIS, -pitch_start * (1.0 - s))
    return ankle, axis_rotation(Y_AXIS, pitch), toe


def gait_track(
    scene: Scene,
    frequency: float,
    duty: float,
    offset: float,
    plant_at: Callable[[np.ndarray], np.ndarray],
    heel_rocker: float,
    toe_off: float,
    clearance: float,
    lift: float = SWING_LIFT,
    hang: float = 0.0,
) -> FootTrack:
    """One foot of a cyclic gait (walk, run).

    Args:
        frequency: strides per second; ``offset`` the foot's phase at t = 0.
        duty: stance fraction of the cycle (about 0.62 walking, under 0.4 running).
        plant_at: cycle indices ``(T,)`` -> ``(T, 3)`` ankle positions (foot flat) of the
            footprints; in cycle ``k`` the foot stands on footprint ``k``, then swings to ``k + 1``.
        heel_rocker, toe_off: foot pitch (radians) at heel strike (toes up) and toe-off.
        clearance: ankle lift at mid-swing (metres).
        lift: fraction of the swing spent lifting straight up and setting straight down.
        hang: extra toe-down pitch of the foot at mid-swing (radians), see :func:`swing_between`.
    """
    geom = FootGeometry.of(scene)
    cycle, ph = phase(scene.times, frequency, offset)
    here, nxt = plant_at(cycle), plant_at(cycle + 1)
    stance = ph < duty
    u = ph / duty
    pitch = np.where(
        u < HEEL_RISE_START,
        -heel_rocker * (1.0 - smoothstep(u / HEEL_ROCKER_END)),
        toe_off * smoothstep(window(u, HEEL_RISE_START, 1.0)),
    )
    on_ball = u >= HEEL_RISE_START
    pivot = here + np.where(on_ball[:, None], geom.ball, geom.heel)
    ankle, rot, toe = foot_pose(geom, pivot, pitch, on_ball)
    tau = (ph - duty) / (1.0 - duty)
    s_ankle, s_rot, s_toe = swing_between(
        geom, tau, here + geom.ball, nxt + geom.heel, clearance, toe_off, -heel_rocker, lift, hang
    )
    return FootTrack(
        np.where(stance[:, None], ankle, s_ankle),
        np.where(stance[:, None, None], rot, s_rot),
        np.where(stance[:, None, None], toe, s_toe),
        stance,
    )


def centre_of_pressure(
    scene: Scene,
    times: np.ndarray,
    frequency: float,
    duty: float,
    offset: float,
    plant_at: Callable[[np.ndarray], np.ndarray],
) -> tuple[np.ndarray, np.ndarray]:
    """Where a foot of :func:`gait_track` (same arguments, at ``times (T,)`` s, which may
    reach beyond the clip) presses on the floor while it stands: ``(T, 3)`` from the heel at
    heel strike to the ball at toe-off (smoothstep over stance; the heel-to-toe rollover of
    the centre of pressure, Perry & Burnfield ch. 4), and the stance progress ``(T,)`` 0..1
    (NaN while the foot swings)."""
    geom = FootGeometry.of(scene)
    cycle, ph = phase(times, frequency, offset)
    u = ph / duty
    roll = smoothstep(np.clip(u, 0.0, 1.0))[:, None]
    cop = plant_at(cycle) + geom.heel + roll * (geom.ball - geom.heel)
    cop[:, 2] = 0.0
    return cop, np.where(ph < duty, u, np.nan)


def pelvis_height_limit(
    scene: Scene, root_xy: np.ndarray, trunk: np.ndarray, ankles: np.ndarray, reach: float = 0.985
) -> np.ndarray:
    """``(T,)`` highest root height at which both hips reach their ankles ``(T, 2, 3)`` with
    legs at most ``reach`` of full length; ``trunk (T, 3, 3)`` is the root times pelvis
    rotation and ``root_xy (T, 2)`` the root's floor position."""
    limit = np.full(scene.n_frames, np.inf)
    max_leg = reach * scene.leg_length
    for s, side in enumerate(("L", "R")):
        hip_rel = np.einsum("tab,b->ta", trunk, scene.offset(f"Bip01 {side} Thigh"))
        horizontal = np.linalg.norm(root_xy + hip_rel[:, :2] - ankles[:, s, :2], axis=-1)
        vertical = np.sqrt(np.maximum(max_leg**2 - horizontal**2, 0.0))
        limit = np.minimum(limit, ankles[:, s, 2] + vertical - hip_rel[:, 2])
    return limit
