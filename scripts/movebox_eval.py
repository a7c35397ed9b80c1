"""``avatarsim eval movebox``: MoveBox's retargeting, roll recovery, smoothing, loops and lip
sync measured against ground truth, and the physics of its output.

Per take (built-in activities, or one real clip per mocap source) and per sensor (Kinect V2,
Azure Kinect):

- ``retarget_err_cm``: mean body17 error of the retargeting stage alone, at the sensor's
  30 Hz, over frames whose body17-driving joints are all Tracked; ``noise_free`` (exact
  joints) and ``sensed`` (the ``Kinect`` device's skeleton: tracked on the rendered depth,
  or with ``skeleton="oracle-noise"`` the truth plus noise, not a sensor) beside
  ``kinect_err_cm``, the error of the sensed Kinect joints themselves.
- ``roll_err_deg``: mean absolute twist of the limb bones (upper arms, forearms, thighs,
  calves) between truth and retargeting, noise-free, with roll recovery (``rest``) and with
  the sensor's roll (``sensor``); built-in takes only (the truth must be on the avatar rig).
- ``jitter_m_s3``: RMS jerk of the body17 joints of the 90 Hz output, sensed input, without
  smoothing (sample-and-hold) and with it; ``truth`` for reference.
- ``method``: the whole method (streaming clock, tracking-state rules, smoothing) scored on
  the 90 Hz clock (:func:`scripts.method_score.score_method`), with every physics check;
  ``err_cm`` over every tick, ``err_cm_tracked`` over the ticks that show a Kinect frame
  tracking every body17 joint. Read them with ``tracked_frames_frac``: a performer who
  leaves the sensor's view or range (a run across the room: CMU 09_01, 35_17, 102_01) is
  NotTracked there, MoveBox holds the last pose where they left, and ``err_cm`` then
  measures how far they went, not the retargeting.
- ``loop_seam``: similarity index across the seam of the output looped naively (last frame
  to first) and trimmed (:func:`synthesis.movebox.similarity.loop_points`).

MoveBox drives what it drives in a scenario (:func:`synthesis.movebox.resize.avatar_for` of
the humanoid's skeleton): a built-in take's own avatar rig, a Bandai clip's avatar sized to it
segment by segment (:func:`sim.humanoid.humanoid_for`), for a rig with a body of its own
(CMU) the avatar resized to the clip's standing height;
``resized_avatar`` is the noise-free retargeting onto the paper's avatar resized uniformly to
the height measured from the Kinect's head and foot joints (§III-B4), whose proportions are
not the user's. ``lip_sync`` (with ``--audio``) correlates the jaw with each WAV's RMS
envelope.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from avatarsim.avatar_models import Motion, quat
from avatarsim.avatar_models.body.errors import RestPoseNotUprightError
from avatarsim.avatar_models.formats import load_motion
from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.measure import standing_height
from avatarsim.avatar_models.rigs import body17_positions, load_rig
from avatarsim.render_cams.device import motion_at_rate
from avatarsim.render_cams.kinect import (
    Kinect,
    KinectSkeletonStream,
    TrackingState,
    kinect_skeleton,
    read_kinect_skeleton,
)
from avatarsim.render_cams.kinect.sensors import KINECT_RATE_HZ, get_sensor
from avatarsim.render_cams.kinect.skeleton import ORACLE_NOTE
from avatarsim.render_cams.kinect.tracker import SKELETON_SOURCE
from avatarsim.render_cams.vr import VRSetup
from avatarsim.scripts.method_score import score_method
from avatarsim.sim.humanoid import Humanoid, humanoid_for
from avatarsim.sim.thresholds import CheckConfig
from avatarsim.synthesis.base import SynthesisError, on_clock
from avatarsim.synthesis.movebox import MoveBox, check_stream
from avatarsim.synthesis.movebox.face import AudioFormatError, lip_sync, read_wav
from avatarsim.synthesis.movebox.mapping import mapping_for
from avatarsim.synthesis.movebox.resize import avatar_for, resized, user_height_m
from avatarsim.synthesis.movebox.retarget import ROLLS, Retargeting, twist_angle
from avatarsim.synthesis.movebox.similarity import loop_points, seam_index
from avatarsim.synthesis.movebox.synthesizer import DEFAULT_ROLL
from avatarsim.synthesis.scoring import body17_errors_cm

SENSORS = ("kinect-v2", "azure-kinect")
ACTIVITIES = ("walk", "box", "wave", "squat")
LIMB_BONES = tuple(f"Bip01 {s} {b}" for s in "LR" for b in ("UpperArm", "Forearm", "Thigh", "Calf"))
LOOP_SEARCH_S = 1.0
RETARGET_ROLL = "hinge"
"""The roll of the ``retarget_err_cm`` numbers: the hinge roll, which goes beyond the paper
(:data:`~synthesis.movebox.synthesizer.DEFAULT_ROLL`); the tables and the JSON name it."""


@dataclass(frozen=True, eq=False)
class Take:
    """One ground-truth motion, its label, and whether it is on the avatar rig itself
    (built-in takes: the roll error needs the truth's own bone frames)."""

    label: str
    truth: Motion
    own_avatar: bool


def builtin_takes(activities, duration_s: float, seed: int) -> list[Take]:
    return [
        Take(f"builtin/{a}", generate(a, duration_s=duration_s, fps=90.0, seed=seed), True)
        for a in activities
    ]


def real_takes(folder: Path, per_source: int, duration_s: float) -> list[Take]:
    """The first ``per_source`` BVH clips (sorted) of each folder holding any, cut to
    ``duration_s`` and, when faster, brought to the Kinect's 30 Hz (what the sensor sees, and
    a quarter of the frames of a 120 Hz CMU clip to put on the humanoid); a folder without
    BVH clips raises :class:`SynthesisError`."""
    by_folder: dict[Path, list[Path]] = {}
    for path in sorted(folder.rglob("*.bvh")):
        by_folder.setdefault(path.parent, []).append(path)
    if not by_folder:
        raise SynthesisError(f"{folder} holds no .bvh clip")
    takes = []
    for paths in by_folder.values():
        for path in paths[:per_source]:
            motion = load_motion(path)
            frames = min(motion.n_frames, int(duration_s * motion.fps) + 1)
            motion = motion[:frames]
            if motion.fps > KINECT_RATE_HZ:
                motion = motion.resample(KINECT_RATE_HZ)
            takes.append(Take(str(path.relative_to(folder)), motion, False))
    return takes


def filmed(
    motion: Motion, sensor: str = "kinect-v2", seed: int = 0, skeleton: str = SKELETON_SOURCE
) -> KinectSkeletonStream:
    """The ``Kinect`` device's ``skeleton`` stream of ``motion`` (tracked on the rendered
    depth by default): filmed on its own body, or, for a rig whose rest pose does not stand
    (Bandai's), on its humanoid (the motion retargeted onto the avatar body)."""
    kinect = Kinect(sensor, skeleton=skeleton)
    try:
        return kinect.sample(motion, seed).skeleton
    except RestPoseNotUprightError:
        humanoid = humanoid_for(motion)
        return kinect.sample(humanoid.motion, seed, humanoid.body).skeleton


def body17_tracked(kinect: KinectSkeletonStream) -> np.ndarray:
    """``(N,)`` bool: every body17 joint of the stream Tracked."""
    rig = load_rig(kinect.rig)
    idx = rig.body17_indices()
    return (kinect.states[:, idx] == TrackingState.TRACKED).all(axis=1)


def retargeting(kinect: KinectSkeletonStream, target, roll: str) -> Retargeting:
    rig = load_rig(kinect.rig)
    return Retargeting(
        target, mapping_for(kinect.rig), rig.skeleton.rest_positions(), kinect.joint_names, roll
    )


def retargeted(kinect: KinectSkeletonStream, target, roll: str) -> Motion:
    """The retargeting stage alone on every frame of ``kinect`` (30 Hz), as a motion."""
    root, local = retargeting(kinect, target, roll)(
        np.nan_to_num(kinect.positions), kinect.orientations
    )
    return Motion(target, float(kinect.meta["rate_hz"]), root, local)


def shown_tracked(kinect: KinectSkeletonStream, ticks: np.ndarray) -> np.ndarray:
    """``(B,)`` bool: the Kinect frame that each display tick ``ticks (B,)`` shows (the
    latest at or before it, as :class:`MoveBox` shows it) tracks every body17 joint; False
    before the first frame."""
    shown = np.searchsorted(kinect.timestamps, ticks, side="right") - 1
    return (shown >= 0) & body17_tracked(kinect)[np.maximum(shown, 0)]


def mean_cm(err_m: np.ndarray, frames: np.ndarray) -> float:
    """Mean of ``err_m (T, ...)`` over ``frames (T,)`` bool, in cm; NaN over no frame (a
    take that the sensor never tracks whole: a swimmer, CMU 126_01)."""
    return float(100.0 * err_m[frames].mean()) if frames.any() else float("nan")


def body17_err_cm(output: Motion, truth: Motion, frames: np.ndarray) -> float:
    err = np.linalg.norm(body17_positions(output) - body17_positions(truth), axis=-1)
    return mean_cm(err, frames)


def kinect_err_cm(kinect: KinectSkeletonStream, truth: Motion, frames: np.ndarray) -> float:
    """Mean error of the stream's body17 joints against the truth's."""
    idx = load_rig(kinect.rig).body17_indices()
    err = np.linalg.norm(kinect.positions[:, idx] - body17_positions(truth), axis=-1)
    return mean_cm(err, frames)


def roll_err_deg(output: Motion, truth: Motion, frames: np.ndarray) -> float:
    """Mean |twist| (degrees) of the limb bones of ``output`` relative to ``truth`` (both on
    avatar-rig skeletons), about each bone's rest axis."""
    sk = truth.skeleton
    bones = sk.indices(list(LIMB_BONES))
    axes = np.stack([sk.offsets[sk.children(b)[0]] for b in bones])
    axes /= np.linalg.norm(axes, axis=-1, keepdims=True)
    rel = quat.mul(
        quat.conj(truth.global_rotations()[:, bones]), output.global_rotations()[:, bones]
    )
    twist = np.abs(np.rad2deg(twist_angle(rel, axes)))
    return float(np.minimum(twist, 360.0 - twist)[frames].mean())


def rms_jerk(motion: Motion) -> float:
    """RMS third derivative (m/s^3) of the body17 joints."""
    jerk = np.diff(body17_positions(motion), n=3, axis=0) * motion.fps**3
    return float(np.sqrt(np.mean(np.sum(jerk**2, axis=-1))))


def resized_avatar(kinect: KinectSkeletonStream):
    """The avatar resized to the user measured by ``kinect`` (§III-B4)."""
    avatar = load_rig("avatar").skeleton
    return resized(avatar, user_height_m(kinect, avatar))


def evaluate_sensor(
    take: Take,
    humanoid: Humanoid,
    sensor: str,
    seed: int,
    checks: CheckConfig,
    skeleton: str = SKELETON_SOURCE,
) -> dict:
    """Every number of the module docstring for one take and sensor. The Kinect films the
    take on its ``humanoid`` (a real clip's rig retargeted onto the avatar body, whose rest
    pose stands) with its ``skeleton`` (:data:`~render_cams.kinect.SKELETONS`); errors are
    against the take itself, NaN over tracked frames when there are none (the share says
    so)."""
    truth = take.truth
    clean = kinect_skeleton(humanoid.motion, sensor, seed=seed, noise=None, body=humanoid.body)
    kinect = Kinect(sensor, skeleton=skeleton)
    sensed = kinect.sample(humanoid.motion, seed, humanoid.body).skeleton
    truth30 = motion_at_rate(truth, clean.meta["rate_hz"])
    tracked = body17_tracked(sensed)
    target = avatar_for(humanoid.body.skeleton, standing_height(humanoid.motion))
    try:
        uniform = resized_avatar(clean)
    except SynthesisError:  # never a frame with the head and both feet tracked: NaN below
        uniform = None
    row = {
        "tracked_frames_frac": float(tracked.mean()),
        "retarget_err_cm": {
            "noise_free": body17_err_cm(retargeted(clean, target, RETARGET_ROLL), truth30, tracked),
            "sensed": body17_err_cm(retargeted(sensed, target, RETARGET_ROLL), truth30, tracked),
            "kinect_err_cm": kinect_err_cm(sensed, truth30, tracked),
            "resized_avatar": float("nan")
            if uniform is None
            else body17_err_cm(retargeted(clean, uniform, RETARGET_ROLL), truth30, tracked),
        },
    }
    if take.own_avatar:
        row["roll_err_deg"] = {
            roll: roll_err_deg(retargeted(clean, target, roll), truth30, tracked) for roll in ROLLS
        }
    stream = VRSetup().sample(truth, seed=seed)
    raw = MoveBox(sensed, target, tau_s=0.0).run(stream)
    result = score_method(MoveBox(sensed, target), truth, stream, checks)
    smoothed = result.score.output
    row["jitter_m_s3"] = {
        "unsmoothed": rms_jerk(raw),
        "smoothed": rms_jerk(smoothed),
        "truth": rms_jerk(motion_at_rate(truth, smoothed.fps)),
    }
    ticks = on_clock(stream).timestamps
    row["method"] = {
        "err_cm": result.score.err_cm,
        "err_cm_tracked": body17_errors_cm(smoothed, truth, frames=shown_tracked(sensed, ticks)),
        "physics": result.physics,
    }
    search = int(LOOP_SEARCH_S * smoothed.fps)
    start, stop = loop_points(smoothed.local_rot, search)
    row["loop_seam"] = {
        "naive": seam_index(smoothed.local_rot, 0, smoothed.n_frames - 1),
        "trimmed": seam_index(smoothed.local_rot, start, stop),
        "frames": [start, stop],
    }
    return row


def lip_sync_scores(files: list[Path]) -> dict:
    """Per WAV file: Pearson r of the jaw opening with the 10 ms RMS envelope."""
    out = {}
    for path in files:
        rate, samples = read_wav(path)
        sync = lip_sync(samples, rate, 30.0)
        out[path.name] = {"r_jaw_rms": envelope_correlation(sync.jaw, samples, rate, 30.0)}
    return out


def envelope_correlation(opening: np.ndarray, samples: np.ndarray, rate: int, fps: float) -> float:
    """Pearson r of ``opening (T,)`` with the audio's 10 ms RMS envelope sampled at ``fps``."""
    hop = rate // 100
    n = samples.size // hop
    rms = np.sqrt(np.mean(samples[: n * hop].reshape(n, hop) ** 2, axis=1))
    envelope = np.interp(np.arange(opening.size) / fps, (np.arange(n) + 0.5) / 100, rms)
    return float(np.corrcoef(opening, envelope)[0, 1])


def run_movebox_eval(
    takes: list[Take],
    sensors=SENSORS,
    seed: int = 0,
    audio: list[Path] = (),
    progress=None,
    skeleton: str = SKELETON_SOURCE,
) -> dict:
    """``{"takes": {label: {sensor: row}}, "summary": {sensor: means}, "lip_sync": ...,
    "skeleton": ...}``, on the Kinect's ``skeleton`` (:data:`~render_cams.kinect.SKELETONS`)."""
    checks = CheckConfig()
    rows: dict[str, dict] = {}
    for i, take in enumerate(takes):
        humanoid = humanoid_for(take.truth)
        rows[take.label] = {
            s: evaluate_sensor(take, humanoid, s, seed, checks, skeleton) for s in sensors
        }
        if progress is not None:
            progress(i + 1, len(takes), take.label)
    roll = {
        "retargeting": RETARGET_ROLL,
        "method": {s: DEFAULT_ROLL[get_sensor(s).rig] for s in sensors},
    }
    out = {"takes": rows, "summary": summarise(rows, sensors), "roll": roll, "seed": seed}
    out["skeleton"] = skeleton if skeleton == SKELETON_SOURCE else f"{skeleton} ({ORACLE_NOTE})"
    if audio:
        out["lip_sync"] = lip_sync_scores(list(audio))
    return out


def summarise(rows: dict, sensors) -> dict:
    """Means over takes per sensor, split into built-in and real takes; a number NaN on a
    take (no tracked frame) is averaged over the other takes."""
    out = {}
    for source in ("builtin", "real"):
        chosen = [
            r for label, r in rows.items() if label.startswith("builtin/") == (source == "builtin")
        ]
        if not chosen:
            continue
        out[source] = {s: _mean_tree([r[s] for r in chosen]) for s in sensors}
    return out


def _mean_tree(rows: list[dict]):
    first = rows[0]
    if isinstance(first, dict):
        keys = [k for k in first if all(k in r for r in rows) and not isinstance(first[k], list)]
        return {k: _mean_tree([r[k] for r in rows]) for k in keys}
    defined = [v for v in rows if np.isfinite(v)]
    return float(np.mean(defined)) if defined else float("nan")


def audio_files(path: Path) -> list[Path]:
    """The WAV files ``path`` names (a file, or every ``*.wav`` of a folder), each checked
    readable now, before any long work.

    Raises:
        AudioFormatError: a missing path, a folder without WAV files, an unreadable file.
    """
    files = sorted(path.glob("*.wav")) if path.is_dir() else [path]
    if not files:
        raise AudioFormatError(f"{path}: no .wav file in this folder")
    for file in files:
        read_wav(file)
    return files


def recorded_take(folder: Path) -> MoveBox:
    """MoveBox on a recorded Kinect take (:func:`~render_cams.kinect.read_kinect_skeleton`),
    driving the avatar resized to the performer (§III-B4); checked before any long work.

    Raises:
        KinectError: not a recording. SynthesisError: an empty or never-tracked stream.
    """
    kinect = read_kinect_skeleton(folder)
    check_stream(kinect)
    return MoveBox(kinect, resized_avatar(kinect))
