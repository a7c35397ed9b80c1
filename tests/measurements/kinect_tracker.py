"""The Kinect body-part tracker against the truth: the README's Kinect tracker table.

    PYTHONPATH=. OMP_NUM_THREADS=1 taskset -c 0 .venv/bin/python -m \
        tests.measurements.kinect_tracker [MODEL.npz] [--quick]

Rows (Kinect V2, depth noise on, seed 0, the shipped model unless MODEL is given):

- ``parts``: per-pixel part accuracy (argmax of the forest at the classified pixels against
  the rendered labels) and Shotton's mean average precision of the joint proposals at
  0.1 m (one proposal per joint and frame, ranked by confidence over the set; a proposal
  counts when within 0.1 m of the true joint; recall over every joint of every frame), on
  held-out subjects (seeds past the training ones) at yaws 0/45/90/180 deg;
- ``view``: per viewing angle (front 0, 45, side 90, back 180 deg: the sensor turned about
  the performer), the body17 error of the tracked skeleton (after the SDK smoothing) on
  generated takes of held-out subjects and on one real clip of each source (CMU, Bandai -1,
  Bandai -2), filmed on their humanoid: median and mean over the joints not NotTracked,
  the NotTracked share, and the swapped share (a left/right joint nearer the truth of its
  mirror twin than of itself);
- ``speed``: tracker frames/s on one core (classify + propose, no rendering) against 30;
- ``movebox``: MoveBox's full-body error on the tracked skeleton next to the oracle's.
"""

from __future__ import annotations

import dataclasses
import sys
import time

import numpy as np

from avatarsim.avatar_models.body17 import BODY17, MIRROR
from avatarsim.avatar_models.formats import load_motion
from avatarsim.avatar_models.generator import generate, sample_subject
from avatarsim.avatar_models.rigs import body17_positions, load_rig
from avatarsim.render_cams.device import motion_at_rate
from avatarsim.render_cams.kinect.device import Kinect
from avatarsim.render_cams.kinect.parts import N_PARTS
from avatarsim.render_cams.kinect.placement import default_sensor_pose, orbit, performer_target
from avatarsim.render_cams.kinect.skeleton import TrackingState
from avatarsim.render_cams.kinect.tracker import DEFAULT_MODEL, load_tracker
from avatarsim.render_cams.kinect.training import render_training_frames
from avatarsim.render_cams.vr import VRSetup
from avatarsim.sim.humanoid import humanoid_for
from avatarsim.synthesis.movebox import MoveBox
from avatarsim.synthesis.movebox.resize import avatar_for
from avatarsim.synthesis.scoring import score_run
from tests.conftest import MOCAP_DIR

YAWS = {"front": 0.0, "45": 45.0, "side": 90.0, "back": 180.0}
HELD_OUT = 100
"""Held-out subjects are ``HELD_OUT ...`` (training uses ``0 .. subjects - 1``)."""
REAL = {
    "cmu": "cmu/13_33.bvh",
    "bandai-1": "bandai/dataset-1/data/dataset-1_walk_normal_001.bvh",
    "bandai-2": "bandai/dataset-2/data/dataset-2_walk_normal_001.bvh",
}


def average_precision(correct: np.ndarray, confidence: np.ndarray, n_truth: int) -> float:
    """AP of proposals ``correct (N,)`` bool ranked by ``confidence (N,)`` against
    ``n_truth`` true joints (non-interpolated: mean precision at each correct proposal)."""
    order = np.argsort(-confidence, kind="stable")
    hits = correct[order]
    precision = np.cumsum(hits) / np.arange(1, len(hits) + 1)
    return float(np.sum(precision[hits]) / n_truth)


def parts_scores(tracker, config, quick: bool) -> dict:
    """Per-pixel accuracy and mAP at 0.1 m on held-out subjects, per yaw and overall."""
    held = dataclasses.replace(
        config,
        subjects=1 if quick else 2,
        activities=("walk", "box") if quick else config.activities,
        frames_per_clip=2,
        yaw_deg=tuple(YAWS.values()),
    )
    frames, poses, joints = render_training_frames(held, subject_offset=HELD_OUT)
    K = tracker_sensor_K(config)
    per_yaw = {name: {"right": 0, "pixels": 0, "ok": [], "conf": []} for name in YAWS}
    names = list(YAWS)
    for i, (frame, pose, b17) in enumerate(zip(frames, poses, joints, strict=True)):
        acc = per_yaw[names[i % len(names)]]
        rows, cols, _, probs = tracker.classify(frame.depth_mm, frame.body_index, K)
        truth = frame.parts[rows, cols].astype(int) - 1
        labelled = truth >= 0
        acc["right"] += int(np.sum(np.argmax(probs[labelled], 1) == truth[labelled]))
        acc["pixels"] += int(labelled.sum())
        cam, conf = tracker.propose(frame.depth_mm, frame.body_index, K)
        truth_cam = (b17 - pose[:3, 3]) @ pose[:3, :3]
        err = np.linalg.norm(cam - truth_cam, axis=1)
        acc["ok"].append(np.where(np.isfinite(err), err < 0.1, False))
        acc["conf"].append(np.where(conf > 0, conf, -1.0))
    out = {}
    for name, acc in per_yaw.items():
        ok, conf = np.array(acc["ok"]), np.array(acc["conf"])  # (F, 17)
        ap = [average_precision(ok[:, k], conf[:, k], len(ok)) for k in range(N_PARTS)]
        out[name] = {"pixel_acc": acc["right"] / acc["pixels"], "mAP": float(np.mean(ap))}
    return out


def tracker_sensor_K(config) -> np.ndarray:
    from avatarsim.render_cams.kinect.sensors import get_sensor

    return get_sensor(config.sensor).K


def view_errors(truth, body, model, yaw_deg: float, skeleton: str = "tracker") -> dict:
    """Body17 error (cm) of the Kinect skeleton of ``truth`` (on ``body``) from a sensor
    turned ``yaw_deg`` about the performer."""
    front = default_sensor_pose(motion_at_rate(truth, 30.0))
    pose = orbit(front, performer_target(truth), np.radians(yaw_deg))
    kinect = Kinect(sensor_pose=pose, skeleton=skeleton, tracker_model=model)
    stream = kinect.sample(truth, seed=0, body=body).skeleton
    idx = load_rig(stream.rig).body17_indices()
    got = stream.positions[:, idx]
    true = body17_positions(motion_at_rate(truth, 30.0))
    live = stream.states[:, idx] != TrackingState.NOT_TRACKED
    err = np.linalg.norm(got - true, axis=-1)
    twin = np.linalg.norm(got - true[:, MIRROR], axis=-1)
    sided = MIRROR != np.arange(len(BODY17))
    swapped = (twin < err) & live & sided
    return {
        "median_cm": float(100 * np.median(err[live])) if live.any() else float("nan"),
        "mean_cm": float(100 * np.mean(err[live])) if live.any() else float("nan"),
        "not_tracked": float(1.0 - live.mean()),
        "swapped": float(swapped.sum() / max((live & sided).sum(), 1)),
        "per_joint_cm": {
            n: float(100 * np.median(err[live[:, j], j])) if live[:, j].any() else None
            for j, n in enumerate(BODY17)
        },
    }


def takes(quick: bool) -> dict:
    """Label -> (motion, body or None): generated held-out takes and one real clip each."""
    out = {}
    activities = ("walk",) if quick else ("walk", "box", "wave", "squat")
    for a in activities:
        subject = sample_subject(np.random.default_rng([0, HELD_OUT]))
        out[f"gen/{a}"] = (generate(a, subject, 2.0, 30.0, seed=HELD_OUT), None)
    for label, path in REAL.items():
        if quick or not (MOCAP_DIR / path).is_file():
            continue
        clip = load_motion(MOCAP_DIR / path)
        clip = clip[: int(2.0 * clip.fps) + 1].resample(30.0)
        humanoid = humanoid_for(clip)
        out[f"real/{label}"] = (humanoid.motion, humanoid.body)
    return out


def speed(tracker, config) -> float:
    """Tracker frames/s (classify + propose) on frontal held-out frames."""
    held = dataclasses.replace(config, subjects=1, activities=("walk",), yaw_deg=(0.0,))
    frames, _, _ = render_training_frames(held, subject_offset=HELD_OUT)
    K = tracker_sensor_K(config)
    start = time.perf_counter()
    for frame in frames:
        tracker.propose(frame.depth_mm, frame.body_index, K)
    return len(frames) / (time.perf_counter() - start)


def movebox(model, quick: bool) -> dict:
    """MoveBox's full-body error (cm, 90 Hz ticks) on the tracked and the oracle skeleton."""
    out = {}
    for a in ("walk",) if quick else ("walk", "box", "wave"):
        truth = generate(a, duration_s=2.0, fps=90.0, seed=HELD_OUT)
        humanoid = humanoid_for(truth)
        target = avatar_for(humanoid.body.skeleton, 1.75)
        vr = VRSetup().sample(truth, seed=0)
        row = {}
        for skeleton in ("tracker", "oracle-noise"):
            kinect = Kinect(skeleton=skeleton, tracker_model=model)
            stream = kinect.sample(humanoid.motion, seed=0, body=humanoid.body).skeleton
            row[skeleton] = score_run(MoveBox(stream, target), truth, vr).err_cm["full"]
        out[a] = row
    return out


def main() -> None:
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    quick = "--quick" in sys.argv
    model = args[0] if args else DEFAULT_MODEL
    tracker = load_tracker(model)
    from avatarsim.render_cams.kinect.training import TrackerTrainingConfig

    config = TrackerTrainingConfig(
        **{k: tuple(v) if isinstance(v, list) else v for k, v in tracker.meta["config"].items()}
    )
    print(f"model {model}: data hash {tracker.meta['data_hash']}, seed {tracker.meta['seed']}")
    print(f"speed: {speed(tracker, config):.1f} frames/s (one core if run under taskset)")
    for yaw, row in parts_scores(tracker, config, quick).items():
        print(f"parts {yaw:>5}: pixel accuracy {row['pixel_acc']:.3f}  mAP@0.1m {row['mAP']:.3f}")
    print("view errors (cm): median / mean, NotTracked share, swapped share")
    for label, (motion, body) in takes(quick).items():
        cells = []
        for name, yaw in YAWS.items():
            r = view_errors(motion, body, model, yaw)
            cells.append(
                f"{name} {r['median_cm']:5.1f}/{r['mean_cm']:5.1f} "
                f"nt {r['not_tracked']:.2f} sw {r['swapped']:.2f}"
            )
        print(f"{label:>16}: " + " | ".join(cells))
    for activity, row in movebox(model, quick).items():
        tracked, oracle = row["tracker"], row["oracle-noise"]
        print(f"movebox {activity}: tracked {tracked:.1f} cm, oracle {oracle:.1f} cm")


if __name__ == "__main__":
    main()
