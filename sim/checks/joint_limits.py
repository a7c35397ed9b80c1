"""Joint-limit violations: hinges and joint chains beyond the body's anatomical ranges (degrees).

The hinge angles are the motion's exact qpos (:meth:`BodyDescription.qpos_from_motion`), the
ranges MuJoCo's ``jnt_range`` (the body's AAOS ranges). A chain of joints that shares one
anatomical range (:attr:`BodyDescription.chains`: the spine's and the neck's joints, e.g.
CMU's Neck, Neck1, Head) is judged by its total rotation, that of its last segment relative to
the segment above it, as Euler angles in the chain's hinge order, against the range per axis:
what a rig with one joint there would be judged by. Rigs distribute a bend unevenly and even
oppositely over a chain's joints (CMU 14_33: lower neck -19 degrees, upper neck +37, head +16,
34 in all), so a joint's share of the range means nothing alone; each of its hinges is still
held to the whole range. A frame violates when any hinge or chain is beyond its range
by more than ``limit_tolerance_deg``. Hinges (and chains) whose whole range is narrower than
``limit_min_range_deg`` are not checked: they are the small allowances the body gives
degrees of freedom a joint does not have anatomically (knee and elbow varus/valgus, pelvic
girdle) so that replay stays exact, and the skeleton fitting of real mocap puts its error
(and the elbow's carrying angle) there.

``details["violations"]`` names each violating hinge (``"LeftArm:rz"``) or chain
(``"Neck+Neck1+Head:ry"``) with its number of frames and largest excess (degrees); for a
chain also its joints' angles (degrees) at the frame of that excess.
"""

from __future__ import annotations

import mujoco
import numpy as np
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models.body.mjcf import chain_name, hinge_name
from avatarsim.sim.checks.base import CheckResult
from avatarsim.sim.checks.replay import BodyReplay
from avatarsim.sim.thresholds import CheckConfig


def chain_angles(
    replay: BodyReplay,
) -> list[tuple[str, tuple[float, float], np.ndarray, np.ndarray]]:
    """The total angles of the body's joint chains (:attr:`BodyDescription.chains`): the
    rotation of a chain's last segment relative to the segment above the chain, as Euler angles
    in the chain's hinge order (what a rig with one joint there would have).

    Returns:
        ``[(name, (lo, hi), total, parts)]`` per chain and axis: the chain's name
        (:func:`~avatar_models.body.mjcf.chain_name`), its range (radians), the total angle
        ``(T,)`` (radians) and the angles ``(T, n)`` of the chain's own hinges about that axis.
    """
    body, model, qpos = replay.body, replay.model, replay.qpos
    out = []
    for chain in body.chains:
        order = body.hinge_order(chain[0]).lower()
        joints = [body.skeleton.names[j] for j in chain]
        adr = np.array(
            [[model.jnt_qposadr[model.joint(hinge_name(n, a)).id] for n in joints] for a in order]
        )  # (3, n)
        total = Rotation.identity(len(qpos))
        for k in range(len(chain)):
            total = total * Rotation.from_euler(order.upper(), qpos[:, adr[:, k]])
        euler = total.as_euler(order.upper())
        for i, a in enumerate(order):
            rng = body.hinge_ranges[chain[0]][a]
            out.append((chain_name(joints, a), rng, euler[:, i], qpos[:, adr[i]]))
    return out


def _excess_deg(angle: np.ndarray, ranges: np.ndarray) -> np.ndarray:
    """Degrees by which ``angle (T, K)`` is beyond ``ranges (K, 2)`` (0 inside)."""
    lo, hi = np.reshape(ranges, (-1, 2)).T
    return np.degrees(np.maximum(np.maximum(lo - angle, angle - hi), 0.0))


class JointLimitCheck:
    name = "joint_limits"

    def __call__(self, replay: BodyReplay, config: CheckConfig) -> CheckResult:
        model = replay.model
        width = np.degrees(np.diff(model.jnt_range, axis=1)[:, 0])
        hinge = model.jnt_type == mujoco.mjtJoint.mjJNT_HINGE
        hinges = np.flatnonzero(hinge & (width >= config.limit_min_range_deg))
        angle = replay.qpos[:, model.jnt_qposadr[hinges]]  # (T, H)
        names = [model.joint(j).name for j in hinges]
        excess = [_excess_deg(angle, model.jnt_range[hinges])]
        chains = [
            c
            for c in chain_angles(replay)
            if np.degrees(c[1][1] - c[1][0]) >= config.limit_min_range_deg
        ]
        names += [c[0] for c in chains]
        totals = np.stack([c[2] for c in chains], axis=1) if chains else angle[:, :0]
        excess.append(_excess_deg(totals, [c[1] for c in chains]))
        excess = np.concatenate(excess, axis=1)  # (T, H + C)
        worst = excess.max(axis=1) if excess.shape[1] else np.zeros(replay.n_frames)
        violating = excess > config.limit_tolerance_deg
        per_limit = {}
        for k in np.flatnonzero(violating.any(axis=0)):
            t = int(np.argmax(excess[:, k]))
            entry = {"frames": int(violating[:, k].sum()), "max_deg": float(excess[t, k])}
            if k >= len(hinges):  # a chain: how its joints shared the worst frame's total
                entry["angles_deg_at_max"] = np.degrees(chains[k - len(hinges)][3][t]).tolist()
            per_limit[names[k]] = entry
        return CheckResult(
            name=self.name,
            per_frame={"limit_excess_deg": worst},
            values={
                "joint_limit_violation_frac": float(violating.any(axis=1).mean()),
                "limit_excess_deg_max": float(worst.max()),
            },
            flagged=violating.any(axis=1),
            details={"violations": per_limit},
        )
