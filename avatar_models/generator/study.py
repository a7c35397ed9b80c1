"""The ControllerPose user study (§5.1, Figures 7-8) as an activity: a held lower-body pose
while one controller at a time sweeps its group of four spheres.

Lower body: one of the twenty poses of Figure 7, picked by the seed (:data:`STUDY_POSES`,
our reading of the figure: it shows the poses, the text names none). Twelve keep both feet
down (stances, squats, lunges, a hip hinge); eight lift one leg (knee raise, leg forward, leg
out to the side, heel back, each side). §5.1: "participants were permitted to drop their legs
down to the floor to regain balance ... these trials appeared more akin to a series of
repeated high steps": the lifted foot is held up for 1.2-2.5 s, put down for 0.4-0.9 s
(seeded), and lifted again. The pelvis shifts over the support foot while a leg is up.

Arms: sixteen spheres "locked to the front of the body, occupying a fixed volume of 69 x 51
x 22 cm" (§5.1): per hand, a group of four at each of two distances, fully outstretched and
with the elbows bent (22 cm nearer). Each group: straight ahead at shoulder height, at head
height, to the side at shoulder height, at stomach height (51 cm from head to stomach
height: 25 cm above the shoulder, 26 below); the side spheres of the two hands are 69 cm
apart, the ahead ones in front of their shoulders; they move and pitch with the chest (a squat or a
hip hinge carries them along). One controller at a time moves "between
these four points, pausing momentarily at each sphere ... straight, up, side, down, back to
straight ... ~3 seconds" at "a mean translation speed of 1.1 m/s"; here it travels between
spheres at 1.1 m/s (minimum-jerk) and pauses for the rest of each 3 s loop. The groups follow
each other (left near, left far, right near, right far; the seed picks where the clip
starts); the idle hand rests at the side. Sizes scale with the subject's stature over 1.75 m
(the study's volume fits an adult of about that height).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models.generator.curves import keyframes, smoothstep
from avatarsim.avatar_models.generator.feet import FootTrack
from avatarsim.avatar_models.generator.ik import axis_rotation, twist_about
from avatarsim.avatar_models.generator.plan import LimbTarget, Plan, Scene, realise
from avatarsim.avatar_models.generator.poses import Y_AXIS, gaze, heading_rotation, trunk
from avatarsim.avatar_models.generator.standing import home_ankles, leg_targets, reachable_root

REFERENCE_HEIGHT_M = 1.75
VOLUME_CM = (69.0, 51.0, 22.0)  # width, height, depth of the sphere volume (§5.1)
ABOVE_SHOULDER_M = 0.25  # head-height sphere; + 0.26 below = 51 cm
BELOW_SHOULDER_M = 0.26  # stomach-height sphere
AHEAD_INSET_M = 0.0  # ahead, up and down spheres in front of their shoulder
FAR_REACH = 0.92  # fully outstretched: wrist this share of the arm's length from the shoulder
SPEED_M_S = 1.1  # §5.1 mean translation speed
LOOP_S = 3.0  # §5.1: one triangular loop takes about 3 s
GROUPS = (("L", "near"), ("L", "far"), ("R", "near"), ("R", "far"))
CLEAR_SHARE = 0.35  # of the lift done straight up before the foot moves sideways or pitches
MIN_PAUSE_S = 0.1
ENGAGE_S = 0.5  # raising the hand from rest to its group's first sphere, and back
HOLD_S, DOWN_S = (1.2, 2.5), (0.4, 0.9)  # lifted-leg hold and drop-down durations
REST_HAND = (0.2, 0.1, -0.85)  # resting wrist from the shoulder, in arm lengths (88 % reach)
MAX_FOREARM_TURN_RAD = np.radians(70.0)  # the avatar rig's forearm twist is +-80 deg
REST_THUMB = np.array([1.0, 0.0, 0.0])  # the rig's rest (T-pose, palms down) thumb side
SUPPORT_SHIFT = 0.048  # statures: pelvis over the support foot (as the one-leg balance)


@dataclass(frozen=True)
class StudyPose:
    """A lower-body pose, written for the left side where it has one (mirrored for ``R``).

    Attributes:
        name: e.g. ``"lunge_left"``.
        left, right: ankle offsets from their relaxed home, statures (x forward, y left, z up).
        drop: pelvis lowered by this share of the leg length.
        hinge_deg: forward lean of the trunk (hip hinge, squat).
        lifted: ``"L"``/``"R"``: that foot is off the floor (with drop-downs); ``""``: none.
        lifted_pitch_deg: the lifted foot's pitch in the world (toes down positive).
    """

    name: str
    left: tuple[float, float, float] = (0.0, 0.0, 0.0)
    right: tuple[float, float, float] = (0.0, 0.0, 0.0)
    drop: float = 0.0
    hinge_deg: float = 0.0
    lifted: str = ""
    lifted_pitch_deg: float = 0.0


def _both_sides(name: str, left, right, **kw) -> tuple[StudyPose, StudyPose]:
    """The pose with its ``left`` leg leading and its mirror (y offsets negated, swapped)."""
    mirror = lambda p: (p[0], -p[1], p[2])  # noqa: E731
    lifted = kw.pop("lifted", "")
    return (
        StudyPose(f"{name}_left", left, right, lifted="L" if lifted else "", **kw),
        StudyPose(f"{name}_right", mirror(right), mirror(left), lifted="R" if lifted else "", **kw),
    )


STUDY_POSES: tuple[StudyPose, ...] = (
    StudyPose("stand"),
    StudyPose("wide_stance", (0.0, 0.06, 0.0), (0.0, -0.06, 0.0), drop=0.03),
    StudyPose("half_squat", (0.0, 0.03, 0.0), (0.0, -0.03, 0.0), drop=0.18, hinge_deg=15.0),
    StudyPose("deep_squat", (0.0, 0.04, 0.0), (0.0, -0.04, 0.0), drop=0.3, hinge_deg=20.0),
    StudyPose("hip_hinge", drop=0.05, hinge_deg=35.0),
    *_both_sides("lunge", (0.16, 0.0, 0.0), (-0.12, 0.0, 0.0), drop=0.2),
    *_both_sides("side_lunge", (0.0, 0.14, 0.0), (0.0, -0.02, 0.0), drop=0.15),
    *_both_sides("split_stance", (0.1, 0.0, 0.0), (-0.1, 0.0, 0.0), drop=0.06),
    StudyPose("narrow_stance", (0.0, -0.015, 0.0), (0.0, 0.015, 0.0)),
    *_both_sides(
        "knee_raise", (0.1, 0.0, 0.22), (0.0, 0.0, 0.0), lifted=True, lifted_pitch_deg=25.0
    ),
    *_both_sides(
        "leg_forward", (0.24, 0.0, 0.14), (0.0, 0.0, 0.0), lifted=True, lifted_pitch_deg=-5.0
    ),
    *_both_sides("leg_side", (0.0, 0.12, 0.08), (0.0, 0.0, 0.0), lifted=True),
    *_both_sides(
        "heel_back", (-0.1, 0.0, 0.2), (0.0, 0.0, 0.0), lifted=True, lifted_pitch_deg=60.0
    ),
)


def lift_schedule(scene: Scene) -> np.ndarray:
    """``(T,)`` in ``[0, 1]``: how far the lifted leg is up (1: the pose, 0: foot down),
    held for :data:`HOLD_S` and dropped for :data:`DOWN_S` in turn (seeded), easing
    between (module docstring). Starts up, a random part into its hold."""
    t = scene.times - scene.times[0]
    keys, values, now = [0.0], [1.0], -scene.rng.uniform(0.0, HOLD_S[0])
    while now < t[-1] + 1.0:
        up_until = now + scene.rng.uniform(*HOLD_S)
        down_until = up_until + 0.3 + scene.rng.uniform(*DOWN_S)
        keys += [up_until, up_until + 0.3, down_until, down_until + 0.4]
        values += [1.0, 0.0, 0.0, 1.0]
        now = down_until + 0.4
    keys, values = np.array(keys), np.array(values)
    ok = np.concatenate([[True], np.diff(keys) > 0]) & (keys >= 0.0)
    ok[0] = True
    return keyframes(t, keys[ok], values[ok, None])[:, 0]


def sphere_targets(scene: Scene, side: str, reach: str) -> np.ndarray:
    """``(4, 3)`` the wrist at the spheres of one group, in the rest body frame (root at its
    standing height): ahead, up (head height), side, down (stomach height)."""
    size = scene.subject.height_m / REFERENCE_HEIGHT_M
    shoulder = scene.rest(f"Bip01 {side} UpperArm")
    hand = scene.rest(f"Bip01 {side} Hand")
    arm = np.linalg.norm(hand - shoulder)
    sign = 1.0 if side == "L" else -1.0
    far_x = shoulder[0] + FAR_REACH * arm * np.cos(np.arcsin(ABOVE_SHOULDER_M * size / arm))
    x = far_x - (0.0 if reach == "far" else VOLUME_CM[2] / 100.0 * size)
    half_width = 0.5 * VOLUME_CM[0] / 100.0 * size
    y_ahead = shoulder[1] - sign * AHEAD_INSET_M
    return np.array(
        [
            [x, y_ahead, shoulder[2]],
            [x, y_ahead, shoulder[2] + ABOVE_SHOULDER_M * size],
            [x, sign * half_width, shoulder[2]],
            [x, y_ahead, shoulder[2] - BELOW_SHOULDER_M * size],
        ]
    )


def sweep(scene: Scene) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray], np.ndarray]:
    """Wrist targets ``{side: (T, 3)}`` (rest body frame), ``{side: (T,)}`` weight of the
    sweep against rest (1 while that hand works its group), and ``(T,)`` group index."""
    n, t = scene.n_frames, scene.times
    tempo = scene.style.tempo
    loop = LOOP_S / tempo
    group_s = loop + 2.0 * ENGAGE_S  # raise the hand to the group, a loop, lower it
    start = scene.rng.uniform(0.0, len(GROUPS) * group_s)
    clock = (t - t[0] + start) % (len(GROUPS) * group_s)
    group = np.minimum((clock // group_s).astype(int), len(GROUPS) - 1)
    local = clock - group * group_s  # seconds into the group
    targets = {s: np.zeros((n, 3)) for s in "LR"}
    active = {s: np.zeros(n) for s in "LR"}
    for g, (side, reach) in enumerate(GROUPS):
        spheres = sphere_targets(scene, side, reach)
        path = np.vstack([spheres, spheres[:1]])  # straight, up, side, down, straight
        legs = np.linalg.norm(np.diff(path, axis=0), axis=1)
        moving = legs / (SPEED_M_S * tempo)
        pause = max(loop - moving.sum(), MIN_PAUSE_S * len(legs)) / len(legs)
        steps = np.column_stack([moving, np.full(len(legs), pause)]).ravel()
        key_t = np.concatenate([[0.0], np.cumsum(steps)])  # arrive, pause, arrive, ...
        key_p = np.repeat(path, 2, axis=0)[1:]  # p0, p1, p1, p2, p2, ..., p4, p4
        mine = group == g
        targets[side][mine] = keyframes(local[mine] - ENGAGE_S, key_t, key_p)
        # Into the group from rest in the first ENGAGE_S, back to rest in the last.
        active[side][mine] = smoothstep(local[mine] / ENGAGE_S) * smoothstep(
            (group_s - local[mine]) / ENGAGE_S
        )
    return targets, active, group


def controllerpose_study(scene: Scene) -> Plan:
    """The ControllerPose study (module docstring)."""
    n, height = scene.n_frames, scene.subject.height_m
    pose = STUDY_POSES[scene.rng.integers(len(STUDY_POSES))]
    homes = home_ankles(scene)
    up = lift_schedule(scene) if pose.lifted else np.zeros(n)
    feet = {}
    for side, offset in (("L", pose.left), ("R", pose.right)):
        ankle = homes[side] + np.asarray(offset) * height * [1.0, 1.0, 0.0]
        lift = np.asarray(offset)[2] * height
        if side == pose.lifted:
            # Straight up off the floor first and straight down onto it last: the foot moves
            # sideways or pitches only once clear of the floor, so it never slides on it.
            clear = smoothstep((up - CLEAR_SHARE) / (1.0 - CLEAR_SHARE))[:, None]
            ground = homes[side]
            position = ground + clear * (ankle - ground) + up[:, None] * [0.0, 0.0, lift]
            pitch = np.radians(pose.lifted_pitch_deg) * clear[:, 0]
            down = up <= 0.0
        else:
            position = np.broadcast_to(ankle, (n, 3)).copy()
            pitch, down = np.zeros(n), np.ones(n, bool)
        rotation = axis_rotation(Y_AXIS, pitch)
        toe = np.broadcast_to(np.eye(3), (n, 3, 3)).copy()
        feet[side] = FootTrack(position, rotation, toe, down)
    legs, toes = leg_targets(scene, feet, (1.0, 0.1, 0.3))
    standing = scene.skeleton.offsets[0, 2] - scene.style.knee_bend * scene.leg_length
    centre = 0.5 * (feet["L"].ankle[0, :2] + feet["R"].ankle[0, :2])
    root = np.column_stack(
        [
            np.full(n, centre[0]),
            np.full(n, centre[1]),
            np.full(n, standing - pose.drop * scene.leg_length),
        ]
    )
    if pose.lifted:
        support = "R" if pose.lifted == "L" else "L"
        shift = (1.0 if support == "L" else -1.0) * SUPPORT_SHIFT * height
        root[:, 1] += smoothstep(up / 0.5) * shift
    hinge = np.radians(pose.hinge_deg)
    root[:, 0] -= 0.2 * np.sin(hinge) * scene.leg_length  # the hips go back as the trunk leans
    pelvis = axis_rotation(Y_AXIS, np.full(n, 0.5 * hinge))
    root = reachable_root(scene, root, pelvis, feet)
    targets, active, group = sweep(scene)
    plan = Plan(
        root_pos=root,
        root_rot=heading_rotation(0.0, n),
        pelvis=pelvis,
        spine=trunk(scene, 0.5 * hinge),
        head=gaze(scene, 0.0, np.radians(10.0)),
        contacts=np.stack([feet[s].contact for s in "LR"], axis=1),
        joints=toes,
        legs=legs,
        fist=np.full((n, 2), 0.6),  # holding the controllers
        meta={
            "study_pose": pose.name,
            "lifted_leg": pose.lifted or None,
            "sphere_group": [f"{s}_{r}" for s, r in GROUPS],
            "group_per_frame": group.astype(np.int8),
        },
    )
    # The spheres are locked to the front of the body: they move and pitch with the chest,
    # which the legs and trunk of the plan place (realised once without the arms).
    positions, rotations = realise(scene, plan).fk()
    chest = rotations[:, scene.skeleton.index("Bip01 Spine2")]  # (T, 3, 3), identity at rest
    for side in "LR":
        # At rest the hand hangs a little in front of the thigh, the elbow slightly bent.
        rest_shoulder = scene.rest(f"Bip01 {side} UpperArm")
        arm = np.linalg.norm(scene.rest(f"Bip01 {side} Hand") - rest_shoulder)
        sign = 1.0 if side == "L" else -1.0
        rest_hand = rest_shoulder + arm * np.array(REST_HAND) * [1.0, sign, 1.0]
        wrist = rest_hand + active[side][:, None] * (targets[side] - rest_hand)
        shoulder = positions[:, scene.skeleton.index(f"Bip01 {side} UpperArm")]
        wrist = shoulder + np.einsum("tab,tb->ta", chest, wrist - rest_shoulder)
        pole = np.einsum("tab,b->ta", chest, [0.0, sign, -1.0])  # elbow out and down
        plan.arms[side] = LimbTarget(wrist, pole)
    for side, rotation in neutral_grip(scene, plan, chest, active).items():
        plan.arms[side] = LimbTarget(plan.arms[side].position, plan.arms[side].pole, rotation)
    return plan


def neutral_grip(
    scene: Scene, plan: Plan, chest: np.ndarray, active: dict[str, np.ndarray]
) -> dict[str, np.ndarray]:
    """``{side: (T, 3, 3)}`` world hand rotations that hold a controller as VR users do: the
    controller (the hand's rest forearm axis) turned from the forearm halfway to the chest's
    forward axis while the hand works its spheres (``active`` ``{side: (T,)}`` in ``[0, 1]``,
    a wrist bend of at most 45 deg), the thumb side up (the chest's up axis; blended towards
    its forward axis as the hand points up or down, forward when it hangs); the IK gives the
    turn about the forearm to the forearm (pronation/supination). Without it the two-bone IK
    carries the rest pose's palm-down hand into every reach; the turn is kept within
    :data:`MAX_FOREARM_TURN_RAD` of the IK's. ``chest``: ``(T, 3, 3)`` chest rotations.
    """
    sk = scene.skeleton
    _, rotations = realise(scene, plan).fk()
    ahead, up = chest[:, :, 0], chest[:, :, 2]  # (T, 3) chest forward and up
    out = {}
    for side in "LR":
        hand = sk.index(f"Bip01 {side} Hand")
        bone = sk.offsets[hand] / np.linalg.norm(sk.offsets[hand])  # rest forearm axis
        forearm = rotations[:, hand] @ bone  # (T, 3): the rest hand is in line with it
        point = forearm + active[side][:, None] * ahead
        point /= np.linalg.norm(point, axis=1, keepdims=True)
        hint = up + np.abs(np.einsum("ta,ta->t", up, point))[:, None] * ahead
        thumb = hint - np.einsum("ta,ta->t", hint, point)[:, None] * point
        thumb /= np.linalg.norm(thumb, axis=1, keepdims=True)
        rest = np.stack([bone, REST_THUMB, np.cross(bone, REST_THUMB)], axis=1)
        world = np.stack([point, thumb, np.cross(point, thumb)], axis=2)
        relative = np.swapaxes(rotations[:, hand], -1, -2) @ world @ rest.T  # in the forearm
        twist = twist_about(relative, bone)
        angle = Rotation.from_matrix(twist).as_rotvec() @ bone
        kept = axis_rotation(bone, np.clip(angle, -MAX_FOREARM_TURN_RAD, MAX_FOREARM_TURN_RAD))
        out[side] = rotations[:, hand] @ relative @ np.swapaxes(twist, -1, -2) @ kept
    return out
