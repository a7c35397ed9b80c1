"""Retargeting a motion on any rig onto the humanoid by matching body17 positions with IK.

Shapes: ``T`` frames, ``nq`` MuJoCo position coordinates.

Sizing (the choice we made): by default the *humanoid is sized to the source*. The avatar rig
is rebuilt with one length factor per segment kind (thigh, shank, foot, upper arm, forearm,
torso, head) so that its body17 distances equal the source's medians over the clip, with
shoulders and hips placed where the source has them relative to neck and pelvis
(:func:`fitted_body`). The targets are then the source's body17 positions unchanged, so the
residual measures what the rigs cannot share (spine curvature, joint ranges), not a size
mismatch. When a body is given, the *targets are scaled* instead, uniformly about the world
origin by the ratio of both skeletons' standing heights
(:func:`avatar_models.measure.standing_height`), so stride length scales with the body.

IK (:class:`avatar_models.body.ik.HumanoidIK`) steers the 17 body17 sites, with joint limits
from the model and a weak pull towards the rest pose; the residual per frame is the mean
site-to-target distance.

Stance feet (:func:`level_stance_feet`): body17 has no foot orientation, so the first IK pass
leaves a standing foot at whatever pitch joins its ankle and toe targets, often on its toes
(Bandai: heel box ~2 cm up, toe box ~1 cm into the floor), which a physics tracker cannot stand
on. The whole motion is first moved down by :func:`sole_offset` (the source's standing ankles sit
higher than the humanoid's, e.g. on a shoe sole); the residual is measured against these
shifted targets. A second pass then adds, on the frames a foot stands, a flat orientation
target for the foot and toe bodies (the first pass's heading, no pitch or roll) and sets
ankle and toe sites at their heights in the rest pose, which stands flat-footed on the floor;
on the other frames no foot site goes below that height (toes dug into the floor at toe-off
would throw the simulated body up). UHC and PhysDiff clean contact the same way: feet in
stance are put on the ground before physics. Three more repairs make a reference the
simulated feet can walk (Bandai walks: the plain tracker's mean time upright from five start
frames went from 0.8 to 2.7 s): the source's standing foot pitch (ankle to toe; Bandai 40 deg
down, the humanoid 17) is matched before the IK (:func:`match_foot_pitch`), else every frame
tips the foot toes-down; toe joints bend where their box would dip into the floor
(:func:`lift_toes`); and swinging feet keep their soles :data:`SWING_CLEARANCE_M` up
(:func:`clear_swing_feet`), since the humanoid's toe box reaches 7 cm beyond the source's
toe joint and would drag on the floor and trip the body.
"""

from __future__ import annotations

from typing import NamedTuple

import mujoco
import numpy as np
from scipy.spatial.transform import Rotation

from avatar_models import quat
from avatar_models.body import BodyDescription, build_body
from avatar_models.body.anatomy import classify
from avatar_models.body.ik import HumanoidIK, IKSettings, humanoid_model, motion_from_qpos
from avatar_models.body17 import BODY17, INDEX
from avatar_models.errors import MotionValueError, RigError
from avatar_models.foot_contact import contact_mask, horizontal_speed
from avatar_models.measure import standing_height
from avatar_models.motion import Motion
from avatar_models.rigs import body17_positions, load_rig
from sim.soles import (
    box_corners,
    corner_positions,
    foot_bodies,
    sole_boxes,
    subtree_mask,
    thigh_bodies,
    toe_bodies,
)

TEMPLATE_RIG = "avatar"
FOOT_SITES = (("l_ankle", "l_foot"), ("r_ankle", "r_foot"))
"""Per side, the body17 sites on the foot body and on the toe body."""
STANCE_HEIGHT_M = 0.03
"""A foot stands while its toe site is within this of its lowest height in the clip..."""
STANCE_SPEED_M_S = 0.5
"""...and its ankle moves slower than this horizontally (heel strike to toe-off)."""
FOOT_ORIENTATION_COST = 1.0
"""Weight of a stance foot's flat orientation (per rad²) next to the positions' 1 (per m²)."""
SEGMENT_SPANS: dict[str, tuple[tuple[str, str], ...]] = {
    "thigh": (("l_hip", "l_knee"), ("r_hip", "r_knee")),
    "shank": (("l_knee", "l_ankle"), ("r_knee", "r_ankle")),
    "foot": (("l_ankle", "l_foot"), ("r_ankle", "r_foot")),
    "upper_arm": (("l_shoulder", "l_elbow"), ("r_shoulder", "r_elbow")),
    "forearm": (("l_elbow", "l_wrist"), ("r_elbow", "r_wrist")),
    "torso": (("pelvis", "neck"),),
    "head": (("neck", "head"),),
}
"""Segment kind -> the body17 distances its length factor sets (sides averaged). In the
avatar rig each of these distances runs through bones of that one kind only, so one factor
per kind matches them exactly in the rest pose."""


class Retargeted(NamedTuple):
    """``qpos (T, nq)``, the ``motion`` on the humanoid's skeleton, and ``residual_cm (T,)``
    (mean body17 site-to-target distance per frame)."""

    qpos: np.ndarray
    motion: Motion
    residual_cm: np.ndarray


def span_lengths(positions: np.ndarray) -> dict[str, float]:
    """Median over frames of each :data:`SEGMENT_SPANS` distance in body17 ``positions
    (T, 17, 3)``, averaged over the sides."""
    out = {}
    for kind, spans in SEGMENT_SPANS.items():
        a = positions[:, [INDEX[s[0]] for s in spans]]
        b = positions[:, [INDEX[s[1]] for s in spans]]
        out[kind] = float(np.median(np.linalg.norm(a - b, axis=-1), axis=0).mean())
    return out


GIRDLES: dict[str, tuple[str, str]] = {
    "neck": ("l_shoulder", "r_shoulder"),
    "pelvis": ("l_hip", "r_hip"),
}
"""Anchor -> the pair of joints hung from it whose rest placement is copied from the source."""


def trunk_offsets(positions: np.ndarray, anchor: str) -> np.ndarray:
    """``(2, 3)`` median position of the :data:`GIRDLES` pair of ``anchor`` relative to the
    anchor in body17 ``positions (T, 17, 3)``, in a trunk frame (up: pelvis to neck; left:
    from the right to the left joint of the pair, made orthogonal to up; forward: left x up).
    In a rest pose standing upright this frame is the world frame."""
    pair = GIRDLES[anchor]
    p = {n: positions[:, INDEX[n]] for n in ("pelvis", "neck", anchor, *pair)}
    up = p["neck"] - p["pelvis"]
    up /= np.linalg.norm(up, axis=-1, keepdims=True)
    left = p[pair[0]] - p[pair[1]]
    left -= np.sum(left * up, axis=-1, keepdims=True) * up
    left /= np.linalg.norm(left, axis=-1, keepdims=True)
    frame = np.stack([np.cross(left, up), left, up], axis=1)  # (T, 3 axes, 3)
    rel = np.stack([p[pair[0]], p[pair[1]]], axis=1) - p[anchor][:, None]
    return np.median(np.einsum("tab,tkb->tka", frame, rel), axis=0)


def fitted_body(motion: Motion, mass_kg: float = 75.0) -> BodyDescription:
    """The avatar-rig humanoid with each segment kind scaled to ``motion``'s body17
    distances, shoulders and hips placed as the source's (:func:`trunk_offsets`)."""
    rig = load_rig(TEMPLATE_RIG)
    sk = rig.skeleton
    b17 = rig.body17_indices(sk)
    rest = sk.rest_positions()[b17]
    source = body17_positions(motion)
    ours, theirs = span_lengths(rest[None]), span_lengths(source)
    scale = {kind: theirs[kind] / ours[kind] for kind in SEGMENT_SPANS}
    rig_kinds = classify(sk, rig).bone_kind
    # Shoulders and hips: place each where the source has it relative to the neck or the
    # pelvis (the avatar's clavicles are bones of kind "torso", so no length factor alone
    # can set shoulder width and height). Offsets are set before the kind factors apply,
    # hence the division; the bones between anchor and joint are of that joint's kind.
    offsets = sk.offsets.copy()
    rest_all = sk.rest_positions()
    for anchor, pair in GIRDLES.items():
        at = rest_all[int(b17[INDEX[anchor]])]
        for name, rel in zip(pair, trunk_offsets(source, anchor), strict=True):
            j = int(b17[INDEX[name]])
            factor = scale.get(rig_kinds[j], 1.0)
            offsets[j] = rel / factor - (rest_all[sk.parents[j]] - at)
    return build_body(sk.with_offsets(offsets), mass_kg=mass_kg, segment_scale=scale)


def humanoid_body(motion: Motion, mass_kg: float = 75.0) -> BodyDescription:
    """The body a foreign-rig ``motion`` is retargeted onto: the one that the skeleton of
    :func:`fitted_body` builds (``build_body(result.motion.skeleton)``, what a caller
    simulates). fitted_body's own segment scaling also sizes geoms (toe box 1 cm shorter,
    head, masses), and a reference made for other feet than the simulated ones puts the toes
    into the floor."""
    return build_body(fitted_body(motion).skeleton, mass_kg=mass_kg)


def retarget(
    motion: Motion,
    body: BodyDescription | None = None,
    settings: IKSettings | None = None,
    level_feet: bool = False,
    scale_targets: bool | None = None,
    model: mujoco.MjModel | None = None,
) -> Retargeted:
    """Retarget ``motion`` (any rig with a body17 map) onto ``body`` (default:
    :func:`humanoid_body`). ``scale_targets`` (default: whether a body was given) scales
    the targets to the body's standing height; a body made by :func:`humanoid_body` for this
    motion is already its size. ``model`` is the body's compiled MJCF when the caller has
    it (it is only read). Joint limits of the body hold in the result. ``level_feet`` puts
    stance feet flat on the floor and clears swinging ones (module docstring), for physics
    tracking; off by default, since it trades fidelity for it (Bandai walk normal_001: mean
    body17 residual 0.03 -> 0.75 cm, p95 2.4 cm), so the physics checks judge the source's own
    contacts. The body is the one ``build_body(result.motion.skeleton)`` gives, so a
    reference levelled for these feet is simulated with the same feet.

    Raises:
        MotionValueError: the motion's rig has no body17 map.
    """
    try:
        targets = body17_positions(motion)
    except RigError as exc:
        raise MotionValueError(f"cannot retarget: {exc}") from exc
    if scale_targets is None:
        scale_targets = body is not None
    if body is None:
        body = humanoid_body(motion)
    if scale_targets:
        targets = targets * (standing_height(body.skeleton) / standing_height(motion))
    model = humanoid_model(body) if model is None else model
    stance = stance_feet(targets, motion.fps)
    if level_feet:  # without the floor offset below, flat feet would float (Bandai: 6 cm)
        targets = match_foot_pitch(model, targets, stance)
    ik = HumanoidIK(model, BODY17, settings=settings)
    solved = ik.solve(targets)
    qpos, residual_cm = solved.qpos, solved.residual_cm
    if level_feet:
        offset = sole_offset(model, targets, stance)
        qpos[:, 2] -= offset
        targets = targets - [0.0, 0.0, offset]
        qpos = level_stance_feet(model, qpos, stance, settings)
        qpos = lift_toes(model, qpos)
        qpos = clear_swing_feet(model, qpos, swinging_feet(targets, motion.fps) & ~stance)
        sites = np.stack([ik.frame_positions(q) for q in qpos])
        residual_cm = 100.0 * np.linalg.norm(sites - targets, axis=-1).mean(axis=1)
    out = motion_from_qpos(body, qpos, motion.fps)
    out = out.replace(meta={**motion.meta, "retargeted_from": motion.skeleton.name})
    return Retargeted(qpos, out, residual_cm)


def stance_feet(positions: np.ndarray, fps: float) -> np.ndarray:
    """``(T, 2)`` whether the left and right foot stand in body17 ``positions (T, 17, 3)``
    (:data:`STANCE_HEIGHT_M`, :data:`STANCE_SPEED_M_S`)."""
    ankle = positions[:, [INDEX[a] for a, _ in FOOT_SITES]]
    toe_z = positions[:, [INDEX[t] for _, t in FOOT_SITES], 2]
    return contact_mask(
        toe_z,
        STANCE_HEIGHT_M,
        floor=toe_z.min(axis=0),
        horizontal_speed=horizontal_speed(ankle, fps),
        max_horizontal_speed=STANCE_SPEED_M_S,
    )


def match_foot_pitch(model, positions: np.ndarray, stance: np.ndarray) -> np.ndarray:
    """``positions (T, 17, 3)`` with each toe target turned about its ankle so that the
    source's standing foot (ankle to toe) has the humanoid's flat-footed pitch.

    Rigs place the ankle and toe joints differently within the foot (Bandai: the ankle-to-toe
    line points 40 deg down in flat stance, the humanoid's 17 deg), so matching the source's
    toe position rotates the humanoid's foot toes-down by the difference in every frame:
    heels up in stance, toe boxes centimetres into the floor at toe-off and in swing. The
    constant difference (median over the ``stance (T, 2)`` frames) is removed by turning
    the ankle-to-toe vector towards the shank (knee minus ankle) in the leg's plane."""
    out = positions.copy()
    rest = HumanoidIK(model, BODY17).frame_positions(model.qpos0)
    for side, (ankle, toe) in enumerate(FOOT_SITES):
        a, b, k = INDEX[ankle], INDEX[toe], INDEX[ankle.replace("ankle", "knee")]
        foot = positions[:, b] - positions[:, a]
        shank = positions[:, k] - positions[:, a]
        down = np.arctan2(-foot[:, 2], np.linalg.norm(foot[:, :2], axis=-1))
        v = rest[b] - rest[a]
        rest_down = np.arctan2(-v[2], np.linalg.norm(v[:2]))
        if not stance[:, side].any():
            continue
        angle = float(np.median(down[stance[:, side]])) - rest_down
        axis = np.cross(foot, shank)
        axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
        out[:, b] = positions[:, a] + Rotation.from_rotvec(angle * axis).apply(foot)
    return out


def lift_toes(model, qpos: np.ndarray, steps: int = 40) -> np.ndarray:
    """``(T, nq)`` ``qpos`` with each toe joint's flexion (``:ry``) changed, where its box
    dips below the floor, to the nearest angle in its range that keeps the box on or above
    it. Body17 sees the toes only at the ball of the foot, so the IK leaves them straight
    and a foot pitched at push-off puts its toe tip centimetres into the floor; a real foot
    bends at the ball. The toes turn about the ball, so no body17 site moves."""
    out = qpos.copy()
    data = mujoco.MjData(model)
    toes = []
    toe_ids = [model.body(name).id for name in toe_bodies(model)]
    for j in range(model.njnt):
        body = model.jnt_bodyid[j]
        if body in toe_ids and model.joint(j).name.endswith(":ry"):
            geoms = sole_boxes(model, (model.body(body).name,))
            if geoms.size:
                toes.append((geoms[:1], int(model.jnt_qposadr[j]), model.jnt_range[j]))

    def lowest(geom: np.ndarray) -> float:
        mujoco.mj_kinematics(model, data)
        return float(corner_positions(data, geom, box_corners(model, geom))[..., 2].min())

    for t in range(out.shape[0]):  # MuJoCo evaluates one configuration per call
        data.qpos[:] = out[t]
        for geom, adr, (lo, hi) in toes:
            if lowest(geom) >= 0.0:
                continue
            q0 = data.qpos[adr]
            grid = np.linspace(lo, hi, steps + 1)
            heights = np.empty(grid.size)
            for n, angle in enumerate(grid):
                data.qpos[adr] = angle
                heights[n] = lowest(geom)
            ok = heights >= 0.0
            data.qpos[adr] = (
                grid[np.argmin(np.abs(grid - q0) + 1e3 * ~ok)]
                if ok.any()
                else grid[np.argmax(heights)]
            )
        out[t] = data.qpos
    return out


SWING_CLEARANCE_M = 0.03
"""A foot off the floor in the source (not standing) keeps its sole boxes this high."""


SWING_SPEED_M_S = 1.0
"""A foot swings while its ball (toe site) moves faster than this horizontally: push-off,
where the heel rises with the ball still on the floor, is slower."""


def swinging_feet(positions: np.ndarray, fps: float) -> np.ndarray:
    """``(T, 2)`` whether the ball of the left and right foot moves faster than
    :data:`SWING_SPEED_M_S` horizontally in body17 ``positions (T, 17, 3)``."""
    ball = positions[:, [INDEX[t] for _, t in FOOT_SITES]]
    return horizontal_speed(ball, fps) > SWING_SPEED_M_S


def clear_swing_feet(
    model, qpos: np.ndarray, swing: np.ndarray, clearance: float = SWING_CLEARANCE_M
) -> np.ndarray:
    """``(T, nq)`` ``qpos`` with each foot that swings (``swing (T, 2)``) raised,
    where its lowest sole-box corner is below ``clearance``, by bending that leg's hinges
    (damped least squares on the corner's height, the foot's orientation and its
    horizontal position held). The source's swing foot clears its floor by 2 cm at the toe
    joint, but the humanoid's toe box reaches 2 cm below and 7 cm beyond that joint, so a
    swing toe drags along the floor and trips a simulated body."""
    out = qpos.copy()
    data = mujoco.MjData(model)
    legs, boxes = [], []
    for foot, thigh in zip(foot_bodies(model), thigh_bodies(model), strict=True):
        chain = subtree_mask(model, (thigh,)) & ~subtree_mask(model, (foot,))
        chain[model.body(foot).id] = True  # thigh to foot, toes left alone
        legs.append(np.flatnonzero(chain[model.dof_bodyid]))
        geoms = sole_boxes(model, (foot,))
        boxes.append((geoms, box_corners(model, geoms)))
    jac, jrot = np.zeros((3, model.nv)), np.zeros((3, model.nv))
    for t in range(out.shape[0]):  # MuJoCo evaluates one configuration per call
        data.qpos[:] = out[t]
        for side in np.flatnonzero(swing[t]):
            geoms, corners = boxes[side]
            for _ in range(10):
                mujoco.mj_kinematics(model, data)
                mujoco.mj_comPos(model, data)
                points = corner_positions(data, geoms, corners)  # (G, 8, 3)
                g, k = np.unravel_index(np.argmin(points[..., 2]), points.shape[:2])
                deficit = clearance - points[g, k, 2]
                if deficit <= 1e-4:
                    break
                mujoco.mj_jac(model, data, jac, jrot, points[g, k], model.geom_bodyid[geoms[g]])
                j = np.vstack([jac, jrot])[:, legs[side]]
                dq = j.T @ np.linalg.solve(j @ j.T + 1e-4 * np.eye(6), [0, 0, deficit, 0, 0, 0])
                full = np.zeros(model.nv)
                full[legs[side]] = dq
                mujoco.mj_integratePos(model, data.qpos, full, 1.0)
        out[t] = data.qpos
    return out


def sole_offset(model, positions: np.ndarray, stance: np.ndarray) -> float:
    """How far (m) the source's standing ankles are above the humanoid's flat-footed ones:
    median over the ``stance (T, 2)`` frames of body17 ``positions (T, 17, 3)``. A source
    floor at the shoe sole (or a thicker foot) puts them higher; the whole motion is moved
    down by this (a constant floor calibration, not a pose change) so a levelled foot can
    reach the floor with the leg the source has."""
    ankles = [BODY17.index(a) for a, _ in FOOT_SITES]
    rest = HumanoidIK(model, BODY17).frame_positions(model.qpos0)[ankles, 2]
    heights = positions[:, ankles, 2] - rest
    return float(np.median(heights[stance])) if stance.any() else 0.0


def level_stance_feet(
    model, qpos: np.ndarray, stance: np.ndarray, settings: IKSettings | None = None
) -> np.ndarray:
    """``(T, nq)`` ``qpos`` re-solved with the feet flat on the floor where ``stance (T, 2)``
    (module docstring); other frames keep their body17 positions and foot orientations."""
    sites = [s for pair in FOOT_SITES for s in pair]
    ik = HumanoidIK(model, BODY17, settings=settings)
    cost = np.where(np.isin(BODY17, sites), FOOT_ORIENTATION_COST, 0.0)
    levelled = HumanoidIK(model, BODY17, orientation_cost=cost, settings=settings)
    ids = [BODY17.index(s) for s in sites]
    rest = ik.frame_positions(model.qpos0)[ids]  # flat-footed on the floor
    n = qpos.shape[0]
    positions = np.empty((n, len(BODY17), 3))
    orientations = np.tile([1.0, 0.0, 0.0, 0.0], (n, len(BODY17), 1))
    data = ik.configuration.data
    for t in range(n):  # MuJoCo evaluates one configuration per call
        positions[t] = ik.frame_positions(qpos[t])
        for k in ids:
            mujoco.mju_mat2Quat(orientations[t, k], data.site_xmat[model.site(BODY17[k]).id])
    positions[:, ids, 2] = np.maximum(positions[:, ids, 2], rest[:, 2])
    for side, (ankle, toe) in enumerate(FOOT_SITES):
        a, b = BODY17.index(ankle), BODY17.index(toe)
        on = stance[:, side]
        forward = positions[on, b, :2] - positions[on, a, :2]
        rest_foot = rest[2 * side + 1] - rest[2 * side]
        yaw = np.arctan2(forward[:, 1], forward[:, 0]) - np.arctan2(rest_foot[1], rest_foot[0])
        flat = Rotation.from_euler("z", yaw[:, None])
        orientations[on, a] = orientations[on, b] = quat.from_scipy(flat)
        positions[on, a, 2] = rest[2 * side, 2]
        positions[on, b] = positions[on, a] + flat.apply(rest_foot)
    return levelled.solve(positions, orientations, q_init=qpos[0]).qpos
