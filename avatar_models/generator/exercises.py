"""Activities in place: arms in and out, wave, squat, lunge, front kick, one-leg balance.

Cycle times at tempo 1: the arms in and out every 3 s, waving 2 Hz (a hand wave's typical
side-to-side rate), a squat every 2.5 s, a lunge every 2.4 s, a kick every 1.6 s. Depths
scale with stature and amplitude.
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models.generator.curves import keyframes, phase, smoothstep, window
from avatarsim.avatar_models.generator.feet import (
    FootGeometry,
    FootTrack,
    foot_pose,
    swing_between,
)
from avatarsim.avatar_models.generator.ik import axis_rotation, euler
from avatarsim.avatar_models.generator.plan import LimbTarget, Plan, Scene, sided
from avatarsim.avatar_models.generator.poses import (
    X_AXIS,
    Y_AXIS,
    Z_AXIS,
    arm_angles,
    gaze,
    heading_rotation,
    trunk,
)
from avatarsim.avatar_models.generator.standing import (
    home_ankles,
    leg_targets,
    planted_feet,
    reachable_root,
)

TAU = 2.0 * np.pi


def _rest_root(scene: Scene, drop: np.ndarray | float = 0.0) -> np.ndarray:
    """``(T, 3)`` root over the feet, lowered by ``drop`` metres plus the style's crouch."""
    n = scene.n_frames
    z = scene.skeleton.offsets[0, 2] - scene.style.knee_bend * scene.leg_length - drop
    return np.column_stack([np.zeros(n), np.zeros(n), np.broadcast_to(z, (n,))])


def _hanging_arms(scene: Scene, sides: str = "LR") -> dict[str, np.ndarray]:
    """Relaxed arms hanging at the sides (8 deg abduction, 12 deg elbow flexion)."""
    out = {}
    for side in sides:
        out.update(arm_angles(scene, side, 0.0, np.radians(8.0), np.radians(12.0)))
    return out


ARMS_CYCLE_HZ = 1.0 / 3.0
ARMS_ADDUCTION_RAD = np.radians(60.0)
"""Horizontal adduction of the upper arm at the innermost point of :func:`arms`."""
ARMS_ELBOW_RAD = np.radians(110.0)
"""Elbow flexion at the innermost point of :func:`arms`: the hands end in front of the chest."""


def arms(scene: Scene) -> Plan:
    """AvatarGo's arms task (T1, shared/papers/avatargo.txt §4): from a T-pose, the hands move
    in towards the chest (upper arms forward in the horizontal plane, elbows bending) and back
    out, standing still. Starts and ends each cycle in the T-pose (the rig's rest arms)."""
    n, t = scene.n_frames, scene.times
    depth = 0.5 - 0.5 * np.cos(TAU * ARMS_CYCLE_HZ * scene.style.tempo * t)  # (T,) 0 = T-pose
    amp = min(scene.style.amplitude, 1.0)
    feet = planted_feet(scene)
    legs, toes = leg_targets(scene, feet)
    joints = {**toes}
    for side in "LR":
        joints[f"Bip01 {side} UpperArm"] = sided(
            axis_rotation(Z_AXIS, -depth * amp * ARMS_ADDUCTION_RAD), side
        )
        joints[f"Bip01 {side} Forearm"] = sided(
            axis_rotation(Z_AXIS, -depth * amp * ARMS_ELBOW_RAD), side
        )
    return Plan(
        root_pos=reachable_root(scene, _rest_root(scene), scene.constant(np.eye(3)), feet),
        root_rot=heading_rotation(0.0, n),
        pelvis=scene.constant(np.eye(3)),
        spine=trunk(scene),
        head=gaze(scene, 0.0, 0.0),
        contacts=np.ones((n, 2), bool),
        joints=joints,
        legs=legs,
        fist=np.full((n, 2), 0.6),
    )


def wave(scene: Scene) -> Plan:
    """Standing, waving the raised right hand side to side above the shoulder."""
    n, t, height = scene.n_frames, scene.times, scene.subject.height_m
    style = scene.style
    feet = planted_feet(scene)
    legs, toes = leg_targets(scene, feet)
    shoulder = scene.rest("Bip01 R UpperArm")
    wag = np.sin(TAU * 2.0 * style.tempo * t)
    lateral = 0.07 * height * min(style.amplitude, 1.2)
    hand = np.column_stack(
        [
            np.full(n, shoulder[0] + 0.06 * height),
            shoulder[1] - 0.1 * height + lateral * wag,
            shoulder[2] + 0.2 * height - 0.02 * height * wag**2,
        ]
    )
    # Palm forward, fingers up, the hand tilting with the wave about the forward axis.
    palm_forward = np.array([[0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
    hand_rot = axis_rotation(X_AXIS, -0.35 * wag) @ palm_forward
    joints = {**_hanging_arms(scene, sides="L"), **toes}
    return Plan(
        root_pos=reachable_root(
            scene, _rest_root(scene, 0.01 * height), scene.constant(np.eye(3)), feet
        ),
        root_rot=heading_rotation(0.0, n),
        pelvis=scene.constant(np.eye(3)),
        spine=trunk(scene, 0.0, 0.0, np.radians(3.0)),
        head=gaze(scene, 0.0, np.radians(-3.0)),
        contacts=np.ones((n, 2), bool),
        joints=joints,
        legs=legs,
        arms={"R": LimbTarget(hand, np.broadcast_to([0.0, -1.0, -1.0], (n, 3)), hand_rot)},
        fist=np.zeros((n, 2)),
    )


def squat(scene: Scene) -> Plan:
    """Bodyweight squats: hips back and down, trunk leaning forward, arms raised forward."""
    n, t, height = scene.n_frames, scene.times, scene.subject.height_m
    depth = 0.5 - 0.5 * np.cos(TAU * 0.4 * scene.style.tempo * t)
    amp = min(scene.style.amplitude, 1.1)
    feet = planted_feet(scene, width=1.5)
    legs, toes = leg_targets(scene, feet, (1.0, 0.35, 0.0))
    root = _rest_root(scene, depth * 0.45 * amp * scene.leg_length)
    root[:, 0] -= depth * 0.1 * height * amp
    pelvis = axis_rotation(Y_AXIS, depth * np.radians(15.0))
    root = reachable_root(scene, root, pelvis, feet)
    joints = {**toes}
    for side in "LR":
        joints.update(
            arm_angles(scene, side, depth * np.radians(85.0), np.radians(10.0), np.radians(10.0))
        )
    return Plan(
        root_pos=root,
        root_rot=heading_rotation(0.0, n),
        pelvis=pelvis,
        spine=trunk(scene, depth * np.radians(25.0) * amp),
        head=gaze(scene, 0.0, 0.0),
        contacts=np.ones((n, 2), bool),
        joints=joints,
        legs=legs,
        fist=np.full((n, 2), 0.2),
    )


def lunge(scene: Scene) -> Plan:
    """Forward lunges, alternating legs: step out, sink until the rear knee nears the floor,
    rise, step back. The rear heel lifts off as the body sinks (pivoting on the ball)."""
    n, t, height = scene.n_frames, scene.times, scene.subject.height_m
    cycle, ph = phase(t, 0.42 * scene.style.tempo)
    step = 0.42 * height * min(scene.style.amplitude, 1.15)
    out_tau, back_tau = window(ph, 0.0, 0.25), window(ph, 0.8, 1.0)
    sink = smoothstep(window(ph, 0.28, 0.48)) * (1.0 - smoothstep(window(ph, 0.58, 0.78)))
    geom = FootGeometry.of(scene)
    homes = home_ankles(scene)
    feet = {}
    for side in "LR":
        leading = (cycle % 2 == 0) == (side == "L")
        home = np.broadcast_to(homes[side], (n, 3))
        front = home + [step, 0.0, 0.0]
        a_out, r_out, toe_out = swing_between(
            geom, out_tau, home + geom.ball, front + geom.heel, 0.05 * height
        )
        a_back, r_back, toe_back = swing_between(
            geom, back_tau, front + geom.ball, home + geom.heel, 0.05 * height
        )
        # Heel up to 55 deg in the deep lunge: the rear ankle then stays within its
        # weight-bearing dorsiflexion (40 deg); the toes take the extension (range 70).
        rear_pitch = np.radians(55.0) * sink
        a_rear, r_rear, toe_rear = foot_pose(geom, home + geom.ball, rear_pitch, np.ones(n, bool))
        going_back = ph >= 0.8
        lead_ankle = np.where(going_back[:, None], a_back, a_out)
        lead_rot = np.where(going_back[:, None, None], r_back, r_out)
        lead_toe = np.where(going_back[:, None, None], toe_back, toe_out)
        lifted = ((ph > 0.0) & (ph < 0.25)) | (ph > 0.8)
        feet[side] = FootTrack(
            np.where(leading[:, None], lead_ankle, a_rear),
            np.where(leading[:, None, None], lead_rot, r_rear),
            np.where(leading[:, None, None], lead_toe, toe_rear),
            ~(leading & lifted),
        )
    root = _rest_root(scene, sink * 0.45 * scene.leg_length)
    # The pelvis moves over the middle of the stance while sinking.
    root[:, 0] = (
        0.5 * step * smoothstep(window(ph, 0.05, 0.3)) * (1.0 - smoothstep(window(ph, 0.75, 0.98)))
    )
    trunk_rot = heading_rotation(0.0, n)
    root = reachable_root(scene, root, trunk_rot, feet)
    legs, toes = leg_targets(scene, feet, (1.0, 0.1, 0.0))
    joints = {**toes}
    for side in "LR":
        joints.update(arm_angles(scene, side, 0.0, np.radians(20.0), np.radians(100.0)))
    return Plan(
        root_pos=root,
        root_rot=trunk_rot,
        pelvis=scene.constant(np.eye(3)),
        spine=trunk(scene, np.radians(4.0)),
        head=gaze(scene, 0.0, 0.0),
        contacts=np.stack([feet[s].contact for s in "LR"], axis=1),
        joints=joints,
        legs=legs,
        fist=np.full((n, 2), 0.3),
    )


# Front kick: kicking ankle relative to its home (statures) and foot pitch in the world (deg,
# toes down +) at key fractions of the kick cycle: lift, chamber, snap out, re-chamber, put
# down, stand. At the snap the shank points forward about 50-65 deg from vertical, so a world
# pitch of -10 deg is an ankle plantarflexed by 40-55 deg (AAOS range 50): the instep leads.
KICK_KEYS = np.array([0.0, 0.08, 0.25, 0.38, 0.5, 0.65, 0.72, 1.0])
KICK_POSES = np.array(
    [
        [0.0, 0.0, 0.0, 0.0],
        [0.0, 0.0, 0.04, 0.0],
        [0.12, 0.0, 0.26, 20.0],
        [0.40, 0.0, 0.42, -10.0],
        [0.12, 0.0, 0.26, 20.0],
        [0.0, 0.0, 0.04, 0.0],
        [0.0, 0.0, 0.0, 0.0],
        [0.0, 0.0, 0.0, 0.0],
    ]
)


def kick(scene: Scene) -> Plan:
    """Front snap kicks, alternating legs, from a guard; the pelvis shifts over the support foot."""
    n, t, height = scene.n_frames, scene.times, scene.subject.height_m
    cycle, ph = phase(t, 0.6 * scene.style.tempo)
    key = keyframes(ph, KICK_KEYS, KICK_POSES)
    amp = min(scene.style.amplitude, 1.15)
    kick_offset = key[:, :3] * height * [amp, 1.0, amp]
    feet = {}
    shift = np.zeros(n)
    for side, sign in (("R", -1.0), ("L", 1.0)):
        kicking = (cycle % 2 == 0) == (side == "R")
        home = home_ankles(scene)[side]
        rot = axis_rotation(Y_AXIS, np.where(kicking, np.radians(key[:, 3]), 0.0))
        ankle = home + np.where(kicking[:, None], kick_offset, 0.0)
        feet[side] = FootTrack(
            ankle, rot, np.broadcast_to(np.eye(3), (n, 3, 3)).copy(), ~kicking | (key[:, 2] == 0)
        )
        # Weight over the support foot from lift-off to put-down.
        shift += (
            np.where(kicking, -sign, 0.0)
            * smoothstep(window(ph, 0.0, 0.08))
            * (1 - smoothstep(window(ph, 0.65, 0.8)))
        )
    legs, toes = leg_targets(scene, feet, (0.6, 0.1, 1.0))
    root = _rest_root(scene, 0.03 * scene.leg_length)
    root[:, 1] = 0.045 * height * shift
    # The trunk leans back as the leg snaps out (counterbalance), half of it in the pelvis.
    lean_back = np.radians(12.0) * np.exp(-(((ph - 0.38) / 0.1) ** 2))
    pelvis = axis_rotation(Y_AXIS, -0.5 * lean_back)
    root = reachable_root(scene, root, pelvis, feet)
    joints = {**toes}
    for side in "LR":
        joints.update(
            arm_angles(scene, side, np.radians(35.0), np.radians(20.0), np.radians(110.0))
        )
    return Plan(
        root_pos=root,
        root_rot=heading_rotation(0.0, n),
        pelvis=pelvis,
        spine=trunk(scene, np.radians(5.0) - lean_back),
        head=gaze(scene, 0.0, 0.0),
        contacts=np.stack([feet[s].contact for s in "LR"], axis=1),
        joints=joints,
        legs=legs,
        fist=np.ones((n, 2)),
    )


def balance(scene: Scene) -> Plan:
    """One-leg balance: shift over the support foot, raise the other knee, hold with small
    postural sway (about 1 cm at 0.3 Hz) and arms slightly out. The seed picks the side."""
    n, t, height = scene.n_frames, scene.times - scene.times[0], scene.subject.height_m
    support = str(scene.rng.choice(["L", "R"]))
    raised = "R" if support == "L" else "L"
    sway_phase = scene.rng.uniform(0.0, TAU)
    lift = keyframes(
        t,
        np.array([0.0, 0.25, 0.45, 0.9]),
        np.array([[0.0, 0.0], [0.0, 0.0], [0.0, 0.04], [0.1, 0.24]]) * height,
    )
    feet = planted_feet(scene)
    home = home_ankles(scene)[raised]
    ankle = home + np.column_stack([lift[:, 0], np.zeros(n), lift[:, 1]])
    pitch = np.radians(25.0) * smoothstep(window(t, 0.45, 0.9))
    feet[raised] = FootTrack(ankle, axis_rotation(Y_AXIS, pitch), feet[raised].toe, lift[:, 1] == 0)
    legs, toes = leg_targets(scene, feet, (1.0, 0.1, 0.4))
    side_sign = 1.0 if support == "L" else -1.0
    root = _rest_root(scene, 0.015 * scene.leg_length)
    sway = 0.006 * height * np.sin(TAU * 0.3 * t + sway_phase)
    root[:, 1] = side_sign * 0.048 * height * smoothstep(window(t, 0.0, 0.3)) + sway
    root[:, 0] = 0.5 * sway
    pelvis = euler(np.column_stack([np.full(n, -side_sign * np.radians(3.0)), np.zeros((n, 2))]))
    root = reachable_root(scene, root, pelvis, feet)
    joints = {**toes}
    for side in "LR":
        joints.update(arm_angles(scene, side, np.radians(10.0), np.radians(35.0), np.radians(15.0)))
    contacts = np.stack([feet[s].contact for s in "LR"], axis=1)
    return Plan(
        root_pos=root,
        root_rot=heading_rotation(0.0, n),
        pelvis=pelvis,
        spine=trunk(scene, 0.0, 0.0, -side_sign * np.radians(2.0)),
        head=gaze(scene, 0.0, np.radians(8.0)),
        contacts=contacts,
        joints=joints,
        legs=legs,
        fist=np.zeros((n, 2)),
        meta={"support_foot": support},
    )
