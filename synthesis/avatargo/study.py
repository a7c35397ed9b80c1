"""The user study of AvatarGo (§4-5) in simulation: simulated users, their avatars and scores.

The paper's result is a questionnaire: nine users rated their Sense of Embodiment (agency
and ownership, 0-7) for each condition after each task (§4-5, Fig. 4). Ours is a geometric
proxy (:data:`PROXY`): how far the avatar's joints are from the simulated user's own
joints, and how far its knees bend from the user's, under each condition. Nobody answers a
question here; a smaller distance is not a measured gain in embodiment.

A :class:`SimulatedUser` is a draw of what differs between a real user and their avatar:

- the avatar's leg and arm lengths relative to the user's (within +-``limb_spread``; the
  avatar is then scaled uniformly from the eye height, §3.2, so a longer-legged avatar of the
  user's eye height is what Fig. 2 shows);
- where a person straps the three trackers (:func:`strap`): up to :data:`STRAP_MAX_M` from
  the nominal spot, at the nominal orientation turned about the joint's rest vertical (the
  shank's and the spine's axis: the direction a strap around the foot or a belt slides) by
  up to :data:`STRAP_YAW_MAX_RAD` and tilted by :data:`STRAP_TILT_SD_RAD`;
- which way the user faces during the walk-in.

The conditions (:data:`VARIANTS`) of :func:`study_run`, all on the same user and motion:
``exact`` (§3.3's exact offsets, which calibrate the strap placement away; what is left is
the tracking noise and the avatar's body not being the user's), ``fixed`` (the constant
nominal offsets a fixed-offset system applies to the same straps, Fig. 2's baseline) and
``fixed_any_rotation`` (the fixed offsets with each tracker at a uniformly random rotation:
§3.4's "any initial orientation of the trackers", a worst case, not a person's placement).

The reference is the simulated user's ground truth (:func:`reference`): the joints of the
motion the devices were sampled from, whatever the calibration and the offsets. Hands are
also scored by the palm-to-controller distance, fingers by their signed distance to the
handle, legs by the knee angle of Fig. 2 (:func:`knee_flexion`, the avatar's against the
user's) over all frames and while the user stands.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models import Motion, Skeleton, quat
from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.rigs import identify_rig
from avatarsim.render_cams.vr import FULL_BODY, Attachment, NoiseModel, VRSetup, nominal_attachment
from avatarsim.synthesis.avatargo.synthesizer import ANALYTIC, AvatarGo
from avatarsim.synthesis.avatargo.walk_in import walk_in

PROXY = (
    "geometric proxy: avatar joints against the simulated user's own joints (cm) and knee "
    "angles (deg); the paper's result is a questionnaire (Sense of Embodiment, 9 users, "
    "§4-5), which nothing here reproduces"
)
"""The label every study output carries (see the module docstring)."""
LIMB_SPREAD = 0.10
"""Avatar leg and arm lengths over the user's: uniform in ``1 +- LIMB_SPREAD`` (our choice:
stock avatars of one height differ from their users by a few to ten per cent per limb)."""
STRAP_MAX_M = 0.05
"""Largest distance of a tracker from its nominal spot, uniform in the ball (our choice: a
person straps a puck by eye to within a few centimetres)."""
STRAP_YAW_MAX_RAD = np.radians(15.0)
"""Largest turn of a strapped tracker about the joint's rest vertical, uniform in +-: the
loose direction of a strap around the foot or a belt around the waist (our choice; a puck
set by eye against the foot's or the back's line is off by a few to ~15 degrees)."""
STRAP_TILT_SD_RAD = np.radians(3.0)
"""Standard deviation of the tilt about the two other axes: the puck's base sits flat on the
instep or the belt, so it tilts by a few degrees only (our choice)."""
TRACKERS = ("left_foot_tracker", "right_foot_tracker", "back_tracker")
VARIANTS = ("exact", "fixed", "fixed_any_rotation")
"""The conditions of :func:`study_run` (see the module docstring)."""
STANDING_KNEE_DEG = 30.0
"""The user stands where both knees are flexed less than this from the rest pose (our
choice: the generator's idle stance keeps soft knees at 23 deg)."""
EFFECTORS = {
    "head": "head",
    "l_foot": "l_ankle",
    "r_foot": "r_ankle",
    "root": "pelvis",
    "l_hand": "l_wrist",
    "r_hand": "r_wrist",
}
"""Scored joints: report name -> body17 joint; the first four are AvatarGo's tracked goals
(head, feet, root; :data:`~synthesis.avatargo.synthesizer.SITES` order)."""


@dataclass(frozen=True)
class SimulatedUser:
    """One simulated user (see the module docstring); ``seed`` also seeds the VR noise.
    ``straps`` are the trackers as a person placed them, ``turned_straps`` the same spots at
    uniformly random rotations (the ``fixed_any_rotation`` condition); empty: nominal."""

    seed: int
    leg_scale: float
    arm_scale: float
    heading_rad: float
    straps: dict[str, Attachment] = field(default_factory=dict)
    turned_straps: dict[str, Attachment] = field(default_factory=dict)

    def as_dict(self) -> dict:
        return {
            "seed": self.seed,
            "leg_scale": self.leg_scale,
            "arm_scale": self.arm_scale,
            "heading_deg": float(np.degrees(self.heading_rad)),
            "straps": {d: a.as_dict() for d, a in self.straps.items()},
            "turned_straps": {d: a.as_dict() for d, a in self.turned_straps.items()},
        }


def strap(
    nominal: Attachment,
    rng: np.random.Generator,
    max_shift_m: float = STRAP_MAX_M,
    max_yaw_rad: float = STRAP_YAW_MAX_RAD,
) -> Attachment:
    """``nominal`` as a person straps it: moved uniformly within ``max_shift_m`` (metres) and
    turned by a yaw uniform in ``+-max_yaw_rad`` about the joint's rest vertical after a tilt
    of :data:`STRAP_TILT_SD_RAD` (radians) about its two other axes; the tilt scales with
    ``max_yaw_rad`` (zero with it)."""
    direction = rng.normal(size=3)
    shift = max_shift_m * rng.uniform() ** (1 / 3) * direction / np.linalg.norm(direction)
    tilt = rng.normal(0.0, STRAP_TILT_SD_RAD, 2) * (max_yaw_rad / STRAP_YAW_MAX_RAD)
    yaw = rng.uniform(-max_yaw_rad, max_yaw_rad)
    turn = quat.from_scipy(Rotation.from_euler("xyz", [tilt[0], tilt[1], 0.0]))
    turn = quat.mul(quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), np.array(yaw)), turn)
    return Attachment(nominal.joint, nominal.position + shift, quat.mul(turn, nominal.rotation))


def sample_user(
    seed: int,
    skeleton: Skeleton,
    limb_spread: float = LIMB_SPREAD,
    max_shift_m: float = STRAP_MAX_M,
    max_yaw_rad: float = STRAP_YAW_MAX_RAD,
) -> SimulatedUser:
    """A random user of ``skeleton``'s rig: limbs within ``1 +- limb_spread``, straps by
    :func:`strap` and heading (see the module)."""
    rng = np.random.default_rng(seed)
    leg, arm = rng.uniform(1.0 - limb_spread, 1.0 + limb_spread, 2)
    straps, turned = {}, {}
    for device in TRACKERS:
        placed = strap(nominal_attachment(device, skeleton), rng, max_shift_m, max_yaw_rad)
        straps[device] = placed
        turned[device] = replace(placed, rotation=quat.from_scipy(Rotation.random(rng=rng)))
    heading = float(rng.uniform(-np.pi, np.pi))
    return SimulatedUser(seed, float(leg), float(arm), heading, straps, turned)


def ideal_user(seed: int = 0, heading_rad: float = 0.0) -> SimulatedUser:
    """A user whose avatar is themself, trackers at the nominal spots."""
    return SimulatedUser(seed, 1.0, 1.0, heading_rad)


def avatar_of(skeleton: Skeleton, user: SimulatedUser) -> Skeleton:
    """``skeleton`` with the user's avatar's leg and arm lengths."""
    legs, arms = user.leg_scale, user.arm_scale
    scale = {"thigh": legs, "shank": legs, "upper_arm": arms, "forearm": arms}
    return build_body(skeleton, segment_scale=scale).skeleton


def setup_for(
    user: SimulatedUser, noise: tuple[NoiseModel, ...] = (), turned: bool = False
) -> VRSetup:
    """The six devices with the user's straps (``turned``: :attr:`SimulatedUser.
    turned_straps`) and ``noise``."""
    return VRSetup(
        devices=FULL_BODY, noise=noise, offsets=user.turned_straps if turned else user.straps
    )


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


def reference(truth: Motion) -> np.ndarray:
    """``(T, E, 3)`` the simulated user's own :data:`EFFECTORS` joints in ``truth``, the
    motion the devices were sampled from: the study's reference for every condition."""
    rig = identify_rig(truth.skeleton)
    return truth.global_positions()[
        :, truth.skeleton.indices([rig.body17[j] for j in EFFECTORS.values()])
    ]


def score(truth: Motion, output: Motion, synth: AvatarGo) -> dict:
    """The study's measures for one run (cm, degrees, shares) against the user's own body
    (:func:`reference`); ``synth`` gives the palm, reach and finger records."""
    n = min(truth.n_frames, output.n_frames)
    truth, output = truth[:n], output[:n]
    arig = synth.body.rig
    out_pos = output.global_positions()
    got = out_pos[:, output.skeleton.indices([arig.body17[j] for j in EFFECTORS.values()])]
    err = np.linalg.norm(got - reference(truth), axis=-1)  # (T, E)
    user_knee, avatar_knee = knee_flexion(truth), knee_flexion(output)
    standing = (np.abs(user_knee) < np.radians(STANDING_KNEE_DEG)).all(1)
    knee_err = np.abs(avatar_knee - user_knee)  # (T, 2)
    palm = np.array(synth.palm_distance[-n:]) if synth.palm_distance else np.zeros((0, 2))
    result = {
        "frames": n,
        "standing_frames": int(standing.sum()),
        "effector_err_cm": {k: float(100 * err[:, i].mean()) for i, k in enumerate(EFFECTORS)},
        "knee_err_deg": float(np.degrees(knee_err.mean())),
        "standing_knee_err_deg": (
            float(np.degrees(knee_err[standing].mean())) if standing.any() else float("nan")
        ),
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
    variants: tuple[str, ...] = VARIANTS,
) -> dict:
    """``truth`` performed by ``user`` wearing the six devices with ``noise``; AvatarGo on the
    user's avatar in each of ``variants`` (:data:`VARIANTS`), its IK by ``solver`` (one of
    :data:`~synthesis.avatargo.synthesizer.SOLVERS`). Returns the user, :data:`PROXY` under
    ``"measure"``, per variant :func:`score` (the outputs under ``"motions"``)."""
    if truth.fps != 90.0:
        truth = truth.resample(90.0)  # the output's clock, frame for frame
    avatar = avatar_of(truth.skeleton, user)
    out: dict = {"user": user.as_dict(), "measure": PROXY, "motions": {}}
    for kind in variants:
        setup = setup_for(user, noise, turned=kind == "fixed_any_rotation")
        sample = walk_in(setup, truth, user.seed, user.heading_rad)
        offsets = "exact" if kind == "exact" else "fixed"
        synth = AvatarGo(avatar, sample, offsets=offsets, fingers=fingers, solver=solver)
        motion = synth.run(setup.sample(truth, seed=user.seed))
        out[kind] = score(truth, motion, synth)
        out["motions"][kind] = motion
    return out
