"""A dataset split as ControllerPose examples.

Reads the split through :class:`scripts.dataset.torch_dataset.ShardDataset` (in shard
order) and turns each sample into :class:`~synthesis.controllerpose.examples.Examples`: the
four 2D poses of §4.3 (each controller's composite and torso-normal view as the detector
reports them: ``fisheye_view_uv``, ``fisheye_view_conf``) at the camera frame times, the
VR stream (``vr_*``), and the ground truth ``body17`` at the camera frames. The angle
targets are computed from ``body17`` in the head's heading frame (the ``body17_angles``
label channel is the same parameterisation in the world frame; datasets generated before
it existed lack it).
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.render_cams import TrackingStream
from avatarsim.scripts.dataset.manifest import MANIFEST_FILE, DatasetError, read_manifest
from avatarsim.scripts.dataset.torch_dataset import ShardDataset
from avatarsim.synthesis.controllerpose.examples import (
    Examples,
    VRStream,
    concat,
    recording_examples,
)

NEEDED = (
    "body17",
    "fisheye_view_uv",
    "fisheye_view_conf",
    "vr_time",
    "vr_pos",
    "vr_quat",
    "vr_valid",
)


def manifest_sha256(root: Path) -> str:
    read_manifest(root)  # a folder without a valid manifest is refused here
    return hashlib.sha256((root / MANIFEST_FILE).read_bytes()).hexdigest()


def sample_height(sample: dict, body17: np.ndarray) -> float:
    """The subject's standing height: the generator's, else (mocap) the span from the lowest
    foot keypoint to the highest head keypoint (a few cm short of the skull's top; the same
    height scales truth and prediction, so errors are consistent)."""
    height = sample["json"].get("subject", {}).get("height_m")
    if height:
        return float(height)
    return float(body17[:, 0, 2].max() - body17[:, [12, 16], 2].min())


def split_samples(root: Path, split: str) -> Iterator[tuple[int, dict]]:
    """The samples of ``split`` of dataset ``root`` in shard order, each with its group
    number (the ``group`` of its examples in :func:`load_examples`)."""
    return enumerate(ShardDataset(root, split=split))


def load_examples(root: str | Path, split: str, frame_stride: int = 1) -> Examples:
    """The examples of ``split`` of dataset folder ``root``, every ``frame_stride``-th camera
    frame of each sample (consecutive 30 Hz frames are near duplicates; the paper's study
    captured at 8 FPS, §5.1).

    Raises:
        DatasetError: no such dataset, an empty split, or samples without the fisheye
            keypoints or the VR stream (the config's ``[[devices]]`` must have
            ``fisheye = true`` and ``vr = true``).
    """
    root = Path(root)
    parts = []
    for group, sample in split_samples(root, split):
        missing = [k for k in NEEDED if k not in sample]
        if missing:
            raise DatasetError(
                f"{root}: sample {sample['__key__']} has no {missing}: ControllerPose needs a "
                "dataset with fisheye keypoints and VR (fisheye = true, vr = true in the "
                "config's [[devices]])"
            )
        arrays = {k: sample[k].numpy() for k in NEEDED}
        meta = sample["json"]
        rate = float(meta["channels"]["fisheye"]["rate_hz"])
        n_frames = arrays["fisheye_view_uv"].shape[0]
        frames = np.arange(0, n_frames, frame_stride)
        frame_time = frames / rate
        last = len(arrays["body17"]) - 1
        truth_index = np.minimum(np.rint(frame_time * meta["fps"]).astype(int), last)
        body17 = arrays["body17"].astype(np.float64)[truth_index]
        vr = VRStream(
            arrays["vr_time"].astype(np.float64),
            arrays["vr_pos"],
            arrays["vr_quat"],
            arrays["vr_valid"],
            tuple(meta["channels"]["vr"]["devices"]),
        )
        parts.append(
            recording_examples(
                body17,
                arrays["fisheye_view_uv"][frames],
                arrays["fisheye_view_conf"][frames],
                frame_time,
                vr,
                sample_height(sample, body17),
                group,
            )
        )
    if not parts:
        raise DatasetError(f"{root}: the {split} split has no samples")
    return concat(parts)


def sample_stream(sample: dict) -> tuple[TrackingStream, float]:
    """A dataset sample's recorded VR stream and its subject's standing height."""
    meta = sample["json"]
    stream = TrackingStream(
        tuple(meta["channels"]["vr"]["devices"]),
        sample["vr_time"].numpy(),
        sample["vr_pos"].numpy(),
        sample["vr_quat"].numpy(),
        sample["vr_valid"].numpy(),
        meta={"rate_hz": float(meta["channels"]["vr"]["rate_hz"])},
    )
    return stream, sample_height(sample, sample["body17"].numpy())


def split_streams(root: Path, split: str) -> dict[int, tuple[TrackingStream, float]]:
    """Per group of :func:`load_examples` on ``split``: its VR stream and the subject's
    height (:func:`sample_stream`)."""
    return {group: sample_stream(sample) for group, sample in split_samples(root, split)}


def mocap_files(folder: Path) -> list[Path]:
    """The BVH files of ``folder``'s tree, sorted.

    Raises:
        DatasetError: the folder has no BVH file.
    """
    files = sorted(Path(folder).rglob("*.bvh"))
    if not files:
        raise DatasetError(f"{folder}: no .bvh clip to evaluate on")
    return files


def mocap_examples(
    folder: Path, clips: int, seconds: float, seed: int = 0
) -> tuple[Examples, dict[int, tuple[TrackingStream, float]]]:
    """Held-out real mocap as examples: ``clips`` BVH files spread evenly over ``folder``'s
    (sorted) tree, their first ``seconds`` each, on the humanoid (a foreign rig retargeted)
    and rendered through the simulated devices as the datasets are (projected keypoints,
    VR with realistic noise); with each clip's (group's) VR stream and standing height.

    Raises:
        DatasetError: the folder has no BVH file.
    """
    from avatarsim.avatar_models.formats import load_motion
    from avatarsim.avatar_models.measure import standing_height
    from avatarsim.render_cams.vr import HEADSET_AND_CONTROLLERS, REALISTIC_NOISE, VRSetup
    from avatarsim.scripts.controllerpose.recording import keypoint_recording
    from avatarsim.sim.humanoid import humanoid_for

    files = mocap_files(folder)
    picked = [files[i] for i in np.linspace(0, len(files) - 1, min(clips, len(files))).astype(int)]
    setup = VRSetup(devices=HEADSET_AND_CONTROLLERS, noise=REALISTIC_NOISE)
    parts, streams = [], {}
    for group, path in enumerate(picked):
        motion = load_motion(path)
        humanoid = humanoid_for(motion[: int(seconds * motion.fps)])
        recording = keypoint_recording(humanoid, seed + group)
        truth = humanoid.motion.sample(recording.time)
        stream = setup.sample(humanoid.motion, seed=seed + group)
        vr = VRStream(
            stream.timestamps, stream.positions, stream.quaternions, stream.valid,
            stream.device_names,
        )  # fmt: skip
        height = standing_height(humanoid.motion)
        streams[group] = (stream, height)
        parts.append(
            recording_examples(
                body17_positions(truth),
                recording.uv,
                recording.conf,
                recording.time,
                vr,
                height,
                group,
            )  # fmt: skip
        )
    return concat(parts), streams
