"""Accuracy as ControllerPose §5.3 reports it, and the nearest-neighbour baseline.

§5.3 normalisation (:func:`normalise`): hip centre (``pelvis``) as the origin, the body
turned about the vertical so that the two pelvis keypoints (``l_hip``, ``r_hip``) face
forward (+X), and scaled to a 1.8 m body (by 1.8 m over the subject's standing height).
Errors are 3D Euclidean distances per joint (cm), summarised as mean and SD over all
joint-frames, overall and without the hip and torso points (§5.3 excludes "those three
points": we leave out ``l_hip``, ``r_hip`` and ``neck`` (torso), and ``pelvis``, the origin,
whose error is 0 by construction).
"""

from __future__ import annotations

import numpy as np
import torch

from avatarsim.avatar_models.body17 import BODY17, INDEX
from avatarsim.synthesis.controllerpose.checkpoint import Checkpoint
from avatarsim.synthesis.controllerpose.examples import Examples
from avatarsim.synthesis.controllerpose.fk import forward_kinematics
from avatarsim.synthesis.controllerpose.train import predict, tensors

NORMALISED_HEIGHT_M = 1.8  # §5.3
HIP_AND_TORSO = ("pelvis", "l_hip", "r_hip", "neck")
LIMBS = np.array([i for i, n in enumerate(BODY17) if n not in HIP_AND_TORSO])
NN_CHUNK = 1024


def normalise(positions: np.ndarray, height: np.ndarray) -> np.ndarray:
    """``positions (N, 17, 3)`` and standing ``height (N,)`` -> §5.3's frame (module
    docstring)."""
    centred = positions - positions[:, INDEX["pelvis"] : INDEX["pelvis"] + 1]
    left = centred[:, INDEX["l_hip"]] - centred[:, INDEX["r_hip"]]
    # Turn by -(heading of the hip line's left normal): the hip line to +Y, the body to +X.
    angle = np.arctan2(left[:, 1], left[:, 0]) - np.pi / 2
    c, s = np.cos(-angle), np.sin(-angle)
    x, y = centred[..., 0], centred[..., 1]
    turned = np.stack(
        [c[:, None] * x - s[:, None] * y, s[:, None] * x + c[:, None] * y, centred[..., 2]],
        -1,
    )
    return turned * (NORMALISED_HEIGHT_M / height)[:, None, None]


def joint_errors(predicted: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """``(N, 17)`` Euclidean errors in cm between two normalised ``(N, 17, 3)`` poses."""
    return np.linalg.norm(predicted - truth, axis=-1) * 100.0


def summary(errors_cm: np.ndarray) -> dict:
    """Mean and SD overall and on the limbs, and per joint (:data:`BODY17` names)."""
    limbs = errors_cm[:, LIMBS]
    return {
        "mean_cm": float(errors_cm.mean()),
        "sd_cm": float(errors_cm.std()),
        "limbs_mean_cm": float(limbs.mean()),
        "limbs_sd_cm": float(limbs.std()),
        "per_joint_cm": {n: float(errors_cm[:, i].mean()) for i, n in enumerate(BODY17)},
        "per_joint_sd_cm": {n: float(errors_cm[:, i].std()) for i, n in enumerate(BODY17)},
        "frames": int(errors_cm.shape[0]),
    }


def model_positions(checkpoint: Checkpoint, examples: Examples) -> np.ndarray:
    """The model's keypoints ``(N, 17, 3)`` for ``examples``: its angles through FK with the
    template bone lengths at each subject's height (the user's height is a calibration
    input, as the paper calibrates arm length, §5.1)."""
    angles = predict(checkpoint.model(), tensors(examples, checkpoint.normaliser))
    lengths = torch.from_numpy(
        (checkpoint.template_lengths[None] * examples.height[:, None]).astype(np.float32)
    )
    with torch.no_grad():
        return forward_kinematics(angles, lengths).numpy().astype(np.float64)


def nearest_neighbour_positions(
    checkpoint: Checkpoint, database: Examples, queries: Examples
) -> np.ndarray:
    """The baseline on the same features: each query gets the normalised pose of the
    database example nearest in the checkpoint's normalised feature space (skeletons, found
    flags, VR). Returns ``(N, 17, 3)`` in §5.3's frame."""

    def flat(examples: Examples) -> torch.Tensor:
        f = checkpoint.normaliser.apply(examples.features)
        return torch.from_numpy(
            np.concatenate([f.skeletons.reshape(len(f), -1), f.found.astype(np.float32), f.vr], -1)
        )

    base, query = flat(database), flat(queries)
    base_sq = (base * base).sum(-1)
    nearest = torch.cat(
        [(base_sq[None] - 2.0 * q @ base.T).argmin(-1) for q in torch.split(query, NN_CHUNK)]
    ).numpy()
    poses = normalise(database.positions.astype(np.float64), database.height)
    return poses[nearest]
