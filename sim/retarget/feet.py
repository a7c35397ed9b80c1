"""Feet of a retargeted reference that the physics controller can stand and walk on.

Shapes: ``T`` frames, ``nq`` MuJoCo position coordinates; feet ordered (left, right).

Stance feet (:func:`level_stance_feet`): body17 has no foot orientation, so the first IK pass
leaves a standing foot at whatever pitch joins its ankle and toe targets, often on its toes
(Bandai: heel box ~2 cm up, toe box ~1 cm into the floor), which the physics controller cannot stand
on. The whole motion is first moved down by :func:`sole_offset` (the source's standing ankles sit
higher than the humanoid's, e.g. on a shoe sole); the residual is measured against these
shifted targets. A second pass then adds, on the frames a foot stands, a flat orientation
target for the foot and toe bodies (the first pass's heading, no pitch or roll) and sets
ankle and toe sites at their heights in the rest pose, which stands flat-footed on the floor;
on the other frames no foot site goes below that height (toes dug into the floor at toe-off
would throw the simulated body up). UHC and PhysDiff clean contact the same way: feet in
stance are put on the ground before physics. Three more repairs make a reference the
simulated feet can walk (Bandai walks: the plain controller's mean time upright from five
start frames is 2.7 s with them, 0.8 s without): the source's standing foot pitch (ankle to
toe; Bandai 40 deg down, the humanoid 17) is matched before the IK (:func:`match_foot_pitch`),
else every frame tips the foot toes-down; toe joints bend where their box would dip into the floor
(:func:`lift_toes`); and swinging feet keep their soles :data:`SWING_CLEARANCE_M` up
(:func:`clear_swing_feet`), since the humanoid's toe box reaches 7 cm beyond the source's
toe joint and would drag on the floor and trip the body.
"""

from __future__ import annotations

import mujoco
import numpy as np
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.body.ik import HumanoidIK, IKSettings
from avatarsim.avatar_models.body17 import BODY17, INDEX
from avatarsim.avatar_models.foot_contact import contact_mask, horizontal_speed
from avatarsim.sim.soles import (
    box_corners,
    corner_positions,
    foot_bodies,
    sole_boxes,
    subtree_mask,
    thigh_bodies,
    toe_bodies,
)

FOOT_SITES = (("l_ankle", "l_foot"), ("r_ankle", "r_foot"))
"""Per side, the body17 sites on the foot body and on the toe body."""
STANCE_HEIGHT_M = 0.03
"""A foot stands while its toe site is within this of its lowest height in the clip..."""
STANCE_SPEED_M_S = 0.5
"""...and its ankle moves slower than this horizontally (heel strike to toe-off)."""
FOOT_ORIENTATION_COST = 1.0
"""Weight of a stance foot's flat orientation (per rad²) next to the positions' 1 (per m²)."""


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
