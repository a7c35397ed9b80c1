"""The user study of AvatarGo (§4-5) in simulation: simulated users, their avatars and scores.

A :class:`SimulatedUser` is a draw of what differs between a real user and their avatar:

- the avatar's leg and arm lengths relative to the user's (within +-:data:`LIMB_SPREAD`;
  the avatar is then scaled uniformly from the eye height, §3.2, so a longer-legged avatar
  of the user's eye height is what Fig. 2 shows);
- where the three trackers are strapped: up to :data:`STRAP_MAX_M` from the nominal spot
  and turned by any rotation (§3.4: "any initial orientation of the trackers");
- which way the user faces during the walk-in.

:func:`study_run` runs one user on one motion with exact and with fixed offsets and scores
both (:func:`score`). The reference of the tracked joints (root, feet, head) is where the
*avatar's* joint must be, not the user's: the avatar's joint at the walk-in, carried rigidly
by the user's joint since (``p_t(J_user) + R_t(J_user) H^-1 (p0(J_avatar) - p0(J_user))``,
``H`` the walk-in heading). It equals the user's joint when the avatar is the user; and
with longer avatar legs the avatar's root is higher than the user's, as it must be to stand.
Hands are scored by the palm-to-controller distance, fingers by their signed distance to the
handle, legs by the knee flexion error while the user stands (the bent-leg artefact).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from avatar_models import Motion, Skeleton, quat
from avatar_models.body import build_body
from avatar_models.rigs import identify_rig
from render_cams.vr import FULL_BODY, Attachment, NoiseModel, VRSetup, nominal_attachment
from synthesis.avatargo.synthesizer import ANALYTIC, AvatarGo
from synthesis.avatargo.walk_in import t_pose, walk_in

LIMB_SPREAD = 0.10
"""Avatar leg and arm lengths over the user's: uniform in ``1 +- LIMB_SPREAD`` (issue 13)."""
STRAP_MAX_M = 0.05
"""Largest distance of a tracker from its nominal spot on the body (issue 13)."""
TRACKERS = ("left_foot_tracker", "right_foot_tracker", "back_tracker")
STANDING_KNEE_DEG = 30.0
"""The user stands where both knees are flexed less than this from the rest pose (our
choice: the generator's idle stance keeps soft knees at 23 deg)."""
EFFECTORS = {"head": "head", "l_foot": "l_ankle", "r_foot": "r_ankle", "root": "pelvis"}
"""Scored end effectors: report name -> body17 joint."""


@dataclass(frozen=True)
class SimulatedUser:
    """One simulated user (see the module docstring); ``seed`` also seeds the VR noise."""

    seed: int
    leg_scale: float
    arm_scale: float
    heading_rad: float
    straps: dict[str, Attachment] = field(default_factory=dict)

    def as_dict(self) -> dict:
        return {
            "seed": self.seed,
            "leg_scale": self.leg_scale,
            "arm_scale": self.arm_scale,
            "heading_deg": float(np.degrees(self.heading_rad)),
            "straps": {d: a.as_dict() for d, a in self.straps.items()},
        }


def sample_user(seed: int, skeleton: Skeleton) -> SimulatedUser:
    """A random user of ``skeleton``'s rig: limbs, straps and heading (see the module)."""
    rng = np.random.default_rng(seed)
    leg, arm = rng.uniform(1.0 - LIMB_SPREAD, 1.0 + LIMB_SPREAD, 2)
    straps = {}
    for device in TRACKERS:
        nominal = nominal_attachment(device, skeleton)
        direction = rng.normal(size=3)
        shift = STRAP_MAX_M * rng.uniform() ** (1 / 3) * direction / np.linalg.norm(direction)
        turn = quat.from_scipy(Rotation.random(random_state=rng))
        straps[device] = Attachment(nominal.joint, nominal.position + shift, turn)
    return SimulatedUser(seed, float(leg), float(arm), float(rng.uniform(-np.pi, np.pi)), straps)


def ideal_user(seed: int = 0, heading_rad: float = 0.0) -> SimulatedUser:
    """A user whose avatar is themself, trackers at the nominal spots."""
    return SimulatedUser(seed, 1.0, 1.0, heading_rad)


def avatar_of(skeleton: Skeleton, user: SimulatedUser) -> Skeleton:
    """``skeleton`` with the user's avatar's leg and arm lengths."""
    legs, arms = user.leg_scale, user.arm_scale
    scale = {"thigh": legs, "shank": legs, "upper_arm": arms, "forearm": arms}
    return build_body(skeleton, segment_scale=scale).skeleton


def setup_for(user: SimulatedUser, noise: tuple[NoiseModel, ...] = ()) -> VRSetup:
    """The six devices with the user's straps and ``noise``."""
    return VRSetup(devices=FULL_BODY, noise=noise, offsets=user.straps)


def knee_angle(positions: np.ndarray, skeleton: Skeleton) -> np.ndarray:
    """``(..., 2)`` angle (radians) between thigh and shank of joint positions ``(..., J, 3)``
    of ``skeleton``, left and right."""
    body17 = identify_rig(skeleton).body17
    out = []
    for s in "lr":
        hip, knee, ankle = (
            positions[..., skeleton.index(body17[f"{s}_{j}"]), :] for j in ("hip", "knee", "ankle")
        )
        thigh, shank = knee - hip, ankle - knee
        norms = np.linalg.norm(thigh, axis=-1) * np.linalg.norm(shank, axis=-1)
        out.append(np.arccos(np.clip((thigh * shank).sum(-1) / norms, -1.0, 1.0)))
    return np.stack(out, axis=-1)


def knee_flexion(motion: Motion) -> np.ndarray:
    """``(T, 2)`` knee flexion (radians) from the rig's rest pose (0: as straight as at rest;
    rest knees of the avatar rig sit ~23 deg off the hip-ankle line)."""
    rest = knee_angle(motion.skeleton.rest_positions(), motion.skeleton)
    return knee_angle(motion.global_positions(), motion.skeleton) - rest


def reference(truth: Motion, user: SimulatedUser, synth: AvatarGo) -> np.ndarray:
    """``(T, 4, 3)`` where the avatar's head, feet and root (:data:`EFFECTORS`) must be: the
    avatar's walk-in joints carried rigidly by the user's (see the module docstring)."""
    rig = identify_rig(truth.skeleton)
    joints = truth.skeleton.indices([rig.body17[j] for j in EFFECTORS.values()])
    pos, rot = truth.fk()
    user0 = t_pose(truth, user.heading_rad, 0.0).global_positions()[0, joints]
    avatar = synth.body.skeleton
    arig = synth.body.rig
    placed = synth.t_pose_positions()[avatar.indices([arig.body17[j] for j in EFFECTORS.values()])]
    local = quat.rotate(quat.conj(synth.calibration.roles.heading), placed - user0)
    return pos[:, joints] + np.einsum("tkab,kb->tka", rot[:, joints], local)


def score(truth: Motion, output: Motion, user: SimulatedUser, synth: AvatarGo) -> dict:
    """The study's measures for one run (cm, degrees, shares)."""
    n = min(truth.n_frames, output.n_frames)
    truth, output = truth[:n], output[:n]
    arig = synth.body.rig
    out_pos = output.global_positions()
    got = out_pos[:, output.skeleton.indices([arig.body17[j] for j in EFFECTORS.values()])]
    err = np.linalg.norm(got - reference(truth, user, synth), axis=-1)  # (T, 4)
    user_knee, avatar_knee = knee_flexion(truth), knee_flexion(output)
    standing = (np.abs(user_knee) < np.radians(STANDING_KNEE_DEG)).all(1)
    knee_err = np.abs(avatar_knee - user_knee)[standing]
    palm = np.array(synth.palm_distance[-n:]) if synth.palm_distance else np.zeros((0, 2))
    result = {
        "frames": n,
        "standing_frames": int(standing.sum()),
        "effector_err_cm": {k: float(100 * err[:, i].mean()) for i, k in enumerate(EFFECTORS)},
        "knee_err_deg": float(np.degrees(knee_err.mean())) if knee_err.size else 0.0,
        "palm_cm": float(100 * palm.mean()) if palm.size else float("nan"),
        "unreached_frac": float(np.mean(synth.attached[-n:])) if synth.attached else 0.0,
    }
    if synth.finger_ik is not None:
        sdf = synth.finger_ik.sdf(synth.finger_ik.t).min(-1)  # (F,) closest point per finger
        result["finger_penetration_mm"] = float(1000 * max(0.0, -sdf.min()))
        result["finger_gap_mm"] = float(1000 * np.clip(sdf, 0.0, None).mean())
    return result


def study_run(
    truth: Motion,
    user: SimulatedUser,
    noise: tuple[NoiseModel, ...] = (),
    fingers: bool = True,
    solver: str = ANALYTIC,
) -> dict:
    """``truth`` performed by ``user`` wearing the six devices with ``noise``; AvatarGo with
    exact and with fixed offsets on the user's avatar, its IK by ``solver``
    (one of :data:`~synthesis.avatargo.synthesizer.SOLVERS`). Returns per variant :func:`score`
    (the outputs under ``"motions"``)."""
    if truth.fps != 90.0:
        truth = truth.resample(90.0)  # the output's clock, frame for frame
    setup = setup_for(user, noise)
    sample = walk_in(setup, truth, user.seed, user.heading_rad)
    stream = setup.sample(truth, seed=user.seed)
    avatar = avatar_of(truth.skeleton, user)
    out: dict = {"user": user.as_dict(), "motions": {}}
    for kind in ("exact", "fixed"):
        synth = AvatarGo(avatar, sample, offsets=kind, fingers=fingers, solver=solver)
        motion = synth.run(stream)
        out[kind] = score(truth, motion, user, synth)
        out["motions"][kind] = motion
    return out
