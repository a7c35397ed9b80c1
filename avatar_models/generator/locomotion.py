"""Cyclic locomotion: walk, run, and walking while dribbling a ball with the right hand.

Feet follow :func:`~avatar_models.generator.feet.gait_track`; the pelvis sways, rotates and
lists, and its height is the lower of a bobbing curve and what the legs can reach; the trunk
counter-rotates, arms swing opposite the legs.
Cadence and stride defaults: walking about 0.95 strides/s with a stride of 0.78 stature
(about 1.35 m/s for 1.75 m; Grieve & Gear 1966, Perry & Burnfield ch. 1); running about
1.4 strides/s with 1.3 statures per stride (about 3.2 m/s; Novacheck 1998, Gait & Posture 7).

The whole-body centre of mass, not the pelvis, is planned. Walking moves it as a linear
inverted pendulum over a zero-moment point that rolls from heel to ball of each stance foot
(Kajita et al. 2003), so the floor can push it where it goes: a centre of mass at constant
speed would need the pressure point up to 20 cm ahead of the toes. Running moves it at
constant forward speed on a spring-mass path (ballistic flights). Either way the swinging
legs, a sixth of the mass each, are accounted for: the pelvis surges against them. The running swing
lifts the heel high behind (ankle 0.17 statures up at mid-swing: a tightly folded leg
swings through with less inertia, Novacheck 1998) and the foot hangs toes-down from the
flexed knee.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from avatarsim.avatar_models.generator.bounce import spring_mass_bounce, vaulting_bob
from avatarsim.avatar_models.generator.com import (
    follow_centre_of_mass,
    lipm_centre_of_mass,
    plan_centre_of_mass,
)
from avatarsim.avatar_models.generator.curves import smooth_cap, smoothstep
from avatarsim.avatar_models.generator.feet import (
    SWING_LIFT,
    centre_of_pressure,
    gait_track,
    pelvis_height_limit,
)
from avatarsim.avatar_models.generator.ik import euler
from avatarsim.avatar_models.generator.plan import LimbTarget, Plan, Scene
from avatarsim.avatar_models.generator.poses import arm_angles, gaze, heading_rotation, trunk
from avatarsim.avatar_models.generator.standing import CAP_HALF_WIDTH_S

TAU = 2.0 * np.pi
PENDULUM_PAD_S = 1.5  # exp(-omega * 1.5 s) < 1% for a centre of mass under 1.2 m


@dataclass(frozen=True)
class Gait:
    """Parameters of a gait at tempo and amplitude 1 (angles in degrees, lengths in statures)."""

    cadence: float  # strides per second
    stride: float  # stride length / stature
    speed_range: tuple[float, float]  # m/s, clamps what tempo and amplitude produce
    duty: float  # stance fraction
    heel_rocker: float
    toe_off: float
    clearance: float  # ankle lift at mid-swing / stature
    swing_lift: float  # fraction of the swing lifting straight up and setting down
    swing_hang: float  # extra toe-down foot pitch at mid-swing (the knee flexes under it)
    bob: float  # pelvis vertical oscillation / stature
    crouch: float  # pelvis lowered / leg length
    running: bool  # centre of mass on a spring-mass path instead of a vaulting pelvis
    pelvis_yaw: float
    arm_swing: float
    elbow: float
    lean: float


# The walking heel rises by 38 deg before toe-off: with the pelvis far over the stance foot, a
# flatter late stance dorsiflexes the ankle past the humanoid's 40 deg (the IK then cannot
# reproduce the walk on its own rig).
WALK = Gait(
    0.95, 0.78, (0.85, 1.7), 0.62, 12, 38, 0.055, SWING_LIFT, 0, 0.012, 0.03, False, 5, 18, 15, 2
)
RUN = Gait(1.4, 1.3, (2.2, 4.5), 0.38, 4, 35, 0.17, 0.06, 65, 0.03, 0.08, True, 8, 30, 85, 8)
DRIBBLE = Gait(
    0.85, 0.55, (0.6, 1.1), 0.64, 10, 25, 0.05, SWING_LIFT, 0, 0.01, 0.08, False, 4, 10, 40, 12
)


def _gait_plan(scene: Scene, gait: Gait) -> tuple[Plan, np.ndarray]:
    """The plan of a straight gait along +X and the left foot's phase ``(T,)``."""
    style, n, t = scene.style, scene.n_frames, scene.times
    height = scene.subject.height_m
    frequency = gait.cadence * style.tempo
    speed = np.clip(gait.stride * height * np.sqrt(style.amplitude) * frequency, *gait.speed_range)
    stride = speed / frequency
    swing_amp = np.radians(gait.arm_swing) * style.amplitude
    # The clip starts part-way into the gait (seeded start time); shift it to start at x = 0.
    start_x = speed * t[0]
    tracks, pressure = [], []
    # The walk went on before the clip and goes on after it: the pendulum's centre of mass
    # depends on the pressure a few 1/omega (about 0.3 s) either side, so it is planned wider.
    pad = int(round(PENDULUM_PAD_S * scene.fps))
    padded_times = t[0] + np.arange(-pad, n + pad) / scene.fps
    for side, offset in (("L", 0.0), ("R", 0.5)):
        ankle_rest = scene.rest(f"Bip01 {side} Foot")

        def plant_at(
            k: np.ndarray, off: float = offset, rest: np.ndarray = ankle_rest
        ) -> np.ndarray:
            x = stride * (k + gait.duty / 2 - off) - 0.04 * height - start_x
            return np.stack([x, np.full(k.shape, 0.85 * rest[1]), np.full(k.shape, rest[2])], 1)

        tracks.append(
            gait_track(
                scene,
                frequency,
                gait.duty,
                offset,
                plant_at,
                np.radians(gait.heel_rocker),
                np.radians(gait.toe_off),
                gait.clearance * height * style.amplitude,
                gait.swing_lift,
                np.radians(gait.swing_hang),
            )
        )
        pressure.append(
            centre_of_pressure(scene, padded_times, frequency, gait.duty, offset, plant_at)
        )
    phase_l = (t * frequency) % 1.0
    mid_stance = TAU * (phase_l - gait.duty / 2)
    yaw = -np.radians(gait.pelvis_yaw) * style.amplitude * np.cos(TAU * phase_l)
    pelvis = euler(
        np.stack(
            [np.radians(3.0) * np.cos(mid_stance), np.full(n, np.radians(gait.lean / 2)), yaw], 1
        )
    )
    root_rot = heading_rotation(0.0, n)
    root_xy = np.stack(
        [speed * t - start_x, 0.02 * height * np.cos(mid_stance) * (1 - gait.running)], 1
    )
    rest_z = scene.skeleton.offsets[0, 2]
    if gait.running:
        step_phase = (2.0 * phase_l) % 1.0  # 0 at each touchdown
        bob = spring_mass_bounce(step_phase, 0.5 / frequency, 2.0 * gait.duty)
    else:
        bob = vaulting_bob(mid_stance, gait.bob * height * style.amplitude, 2.0 * frequency)
    nominal = rest_z - (gait.crouch + style.knee_bend) * scene.leg_length + bob
    ankles = np.stack([tr.ankle for tr in tracks], axis=1)
    limit = pelvis_height_limit(scene, root_xy, root_rot @ pelvis, ankles)
    root_pos = np.column_stack([root_xy, smooth_cap(nominal, limit, scene.fps, CAP_HALF_WIDTH_S)])

    joints = {}
    for side, tr in zip("LR", tracks, strict=True):
        sign = 1.0 if side == "L" else -1.0
        swing = -sign * swing_amp * np.cos(TAU * phase_l)
        elbow = np.radians(gait.elbow) + 0.5 * swing_amp * np.clip(swing / swing_amp, 0, 1)
        joints.update(arm_angles(scene, side, swing, np.radians(8.0), elbow))
        joints[f"Bip01 {side} Toe0"] = tr.toe  # about Y: the same on both sides
    pole = np.array([1.0, 0.0, 0.0])
    legs = {
        side: LimbTarget(tr.ankle, np.broadcast_to(pole + [0, 0.1 * sg, 0], (n, 3)), tr.rotation)
        for side, tr, sg in (("L", tracks[0], 1), ("R", tracks[1], -1))
    }
    plan = Plan(
        root_pos=root_pos,
        root_rot=root_rot,
        pelvis=pelvis,
        spine=trunk(scene, np.radians(gait.lean / 2), 1.5 * -yaw),
        head=gaze(scene, 0.0, np.radians(5.0)),
        contacts=np.stack([tr.contact for tr in tracks], axis=1),
        joints=joints,
        legs=legs,
        fist=np.full((n, 2), 0.5 if gait.running else 0.2),
    )
    travel = speed * t - start_x

    def limit_of(xy: np.ndarray) -> np.ndarray:
        return pelvis_height_limit(scene, xy, root_rot @ pelvis, ankles)

    if gait.running:
        plan.root_pos = _spring_mass_root(scene, plan, travel, bob, limit_of)
    else:
        zmp = _zero_moment_point(pressure, gait.duty)
        plan.root_pos = _pendulum_root(scene, plan, zmp, pad, limit_of)
    return plan, phase_l


def _zero_moment_point(pressure: list[tuple[np.ndarray, np.ndarray]], duty: float) -> np.ndarray:
    """``(T, 2)`` wanted zero-moment point of a walk from each foot's centre of pressure and
    stance progress (:func:`~avatar_models.generator.feet.centre_of_pressure`, left then
    right): on the single stance foot, and in double support handed from the trailing foot
    to the leading one (smoothstep over the ``duty - 0.5`` of a cycle both feet stand)."""
    (cop_l, u_l), (cop_r, u_r) = pressure
    double = max(duty - 0.5, 1e-6)
    # Load on the left foot: 1 on it alone, 0 on the right alone, in between while it is the
    # newly landed (rising) or the trailing (falling) foot of a double support.
    newly_l = smoothstep(np.clip(np.nan_to_num(u_l, nan=1.0) * duty / double, 0.0, 1.0))
    newly_r = smoothstep(np.clip(np.nan_to_num(u_r, nan=1.0) * duty / double, 0.0, 1.0))
    both = np.isfinite(u_l) & np.isfinite(u_r)
    leading_l = np.nan_to_num(u_l, nan=1.0) < np.nan_to_num(u_r, nan=1.0)
    load_l = np.where(
        both, np.where(leading_l, newly_l, 1.0 - newly_r), np.isfinite(u_l).astype(float)
    )
    return (load_l[:, None] * cop_l + (1.0 - load_l[:, None]) * cop_r)[:, :2]


def _pendulum_root(
    scene: Scene,
    plan: Plan,
    zmp: np.ndarray,
    pad: int,
    limit_of: Callable[[np.ndarray], np.ndarray],
) -> np.ndarray:
    """``(T, 3)`` root positions whose centre of mass is the linear inverted pendulum over
    ``zmp (pad + T + pad, 2)`` (:func:`~avatar_models.generator.com.lipm_centre_of_mass` at
    the plan's mean centre-of-mass height): it slows over the stance foot and speeds up
    between steps, and sways over each foot, so the floor can give every force it needs.
    Heights are the plan's, lowered smoothly where the legs would not reach their feet (the
    root under ``limit_of(root_xy (T, 2)) (T,)``)."""
    height = plan_centre_of_mass(scene, plan)[:, 2].mean()
    wanted = np.full((scene.n_frames, 3), np.nan)
    wanted[:, :2] = lipm_centre_of_mass(zmp, height, scene.fps)[pad : pad + scene.n_frames]
    root = plan.root_pos
    for _ in range(2):  # lowering the root folds the legs, which moves the centre of mass
        root = follow_centre_of_mass(scene, replace(plan, root_pos=root), wanted)
        root[:, 2] = smooth_cap(root[:, 2], limit_of(root[:, :2]), scene.fps, CAP_HALF_WIDTH_S)
    return follow_centre_of_mass(scene, replace(plan, root_pos=root), wanted)


def _spring_mass_root(
    scene: Scene,
    plan: Plan,
    travel: np.ndarray,
    bounce: np.ndarray,
    limit_of: Callable[[np.ndarray], np.ndarray],
) -> np.ndarray:
    """``(T, 3)`` root positions that make the centre of mass, not the pelvis, travel
    ``travel (T,)`` at constant speed, straight, and bounce by ``bounce (T,)``: ballistic in
    flight, a spring in stance. The bounce's level is as high as the plan's pelvis but low
    enough that the legs reach the ground: the root stays under ``limit_of(root_xy (T, 2))
    (T,)``. Moving the root horizontally changes that limit, so level and path are found
    twice."""
    root = plan.root_pos
    for _ in range(2):
        com = plan_centre_of_mass(scene, replace(plan, root_pos=root))
        offset = com - root
        level = min(
            np.mean(plan.root_pos[:, 2] - bounce + offset[:, 2]),
            np.min(limit_of(root[:, :2]) - bounce + offset[:, 2]),
        )
        wanted = np.column_stack(
            [
                travel + offset[:, 0].mean(),
                np.full(scene.n_frames, com[:, 1].mean()),
                level + bounce,
            ]
        )
        root = follow_centre_of_mass(scene, replace(plan, root_pos=root), wanted)
    return root


def walk(scene: Scene) -> Plan:
    return _gait_plan(scene, WALK)[0]


def run(scene: Scene) -> Plan:
    return _gait_plan(scene, RUN)[0]


def dribble(scene: Scene) -> Plan:
    """Walking slowly while bouncing a ball with the right hand twice per stride, eyes on it."""
    plan, phase_l = _gait_plan(scene, DRIBBLE)
    n, height = scene.n_frames, scene.subject.height_m
    # Hand pushes down quickly and rides the ball up slowly: a skewed cosine over each bounce.
    bounce = (2.0 * phase_l) % 1.0
    down = np.where(bounce < 0.35, bounce / 0.35, 1.0 - (bounce - 0.35) / 0.65)
    low, high = 0.43 * height, 0.55 * height
    hand = np.column_stack(
        [plan.root_pos[:, 0] + 0.2 * height, np.full(n, -0.17 * height), high - (high - low) * down]
    )
    # Fingers forward, palm down (yaw first), then the wrist flexes with the push.
    wrist = euler(
        np.column_stack([np.full(n, np.pi / 2), np.radians(-10 + 40 * down), np.zeros(n)]), "zyx"
    )
    plan.arms["R"] = LimbTarget(hand, np.broadcast_to([-1.0, -0.6, -0.3], (n, 3)), wrist)
    plan.head = gaze(scene, -0.2, np.radians(25.0))
    plan.fist[:, 1] = 0.1
    return plan
