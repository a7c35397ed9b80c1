"""``render_fisheye_sequence``: what the four controller cameras would record for a motion.

Writes, under ``out_dir``:

- ``<camera>/NNNNNN.png``: colour frames (``camera`` is e.g. ``left_controller-ring``), with
  bad frames injected (ControllerPose §4.2, about 1 in 50) when ``bad_frame_rate > 0``;
- ``<camera>/NNNNNN_range.png``: 16-bit range along each pixel's ray in millimetres (0 = none);
- ``keypoints.json``: seed, camera models and one self-describing record per camera frame
  (:mod:`render_cams.fisheye.records`), incl. the bad-frame ground truth and the occlusion
  flags (``occluded``, ``lens_blocked``, ``mean_luminance``: a camera inside or against the
  body records a dark frame, :mod:`render_cams.fisheye.occlusion`); no timings or absolute
  paths, so that the same motion and seed give the same bytes in any folder;
- ``fisheye.mp4``: the four cameras tiled 2x2, for a person to watch.

Frames are rendered at the sensor's 30 Hz (ControllerPose §4.1 cameras); ``scale`` shrinks
the 640x480 images for quick looks.
"""

from __future__ import annotations

import json
import time
from collections.abc import Sequence
from pathlib import Path

import cv2
import imageio.v2 as imageio
import numpy as np

from avatar_models import Motion
from avatar_models.body import BodyDescription
from avatar_models.rigs import body17_positions
from render_cams.device import DeviceError, motion_at_rate, resolve_seed
from render_cams.fisheye import bad_frames, occlusion
from render_cams.fisheye.keypoints import (
    DetectorNoise,
    confidence,
    joint_thickness,
    project_joints,
    visibility,
    world_to_camera,
)
from render_cams.fisheye.model import FisheyeModel
from render_cams.fisheye.records import frame_record
from render_cams.fisheye.render import FisheyeRenderer
from render_cams.fisheye.rig import (
    ControllerCamera,
    Mount,
    camera_poses,
    controller_cameras,
    inside_body,
)
from render_cams.fisheye.stitch import stitch_params
from render_cams.scene import BodyScene, body_for_motion

CAMERA_RATE_HZ = 30.0


def render_fisheye_sequence(
    motion: Motion,
    out_dir: str | Path,
    seed: int | np.random.Generator = 0,
    model: FisheyeModel | None = None,
    scale: float = 1.0,
    rate_hz: float = CAMERA_RATE_HZ,
    bad_frame_rate: float = bad_frames.BAD_FRAME_RATE,
    detector_noise: DetectorNoise | None = None,
    controllers: Sequence[str] = ("left_controller", "right_controller"),
    video: bool = True,
    stitch: bool = True,
    body: BodyDescription | None = None,
    mount: Mount | None = None,
) -> dict:
    """Render every controller camera over ``motion`` into ``out_dir``; return a summary
    ``{"frames", "cameras", "fps_rendered", "bad_frames", "occluded_frames", "seed",
    "out_dir"}``.

    Args:
        body: the humanoid to render (built once by the caller for this motion); ``motion``
            must be on its skeleton. Default: a body built from ``motion``'s skeleton.
        mount: where the cameras sit on the controllers (default :class:`Mount`).

    A camera inside or against the body records a dark, occluded frame, flagged in its
    record (:mod:`render_cams.fisheye.occlusion`); the clip is rendered all the same.

    Raises:
        IntrinsicsError: impossible camera model; DeviceError: bad rate or scale; RigError: a
        skeleton without a body17 map; SceneError: ``motion`` not on ``body``'s skeleton.
    """
    seed = resolve_seed(seed)
    if not (np.isfinite(scale) and 0.05 <= scale <= 4.0):
        raise DeviceError(f"scale must be in [0.05, 4], got {scale}")
    model = model or FisheyeModel.from_fov()
    if scale != 1.0:
        model = model.scaled(scale)
    sampled = motion_at_rate(motion, rate_hz)
    body = body_for_motion(sampled, body)
    cameras = controller_cameras(controllers, mount)
    poses = camera_poses(sampled, cameras)  # (T, C, 4, 4)
    inside = inside_body(body, *sampled.fk(), poses[..., :3, 3])  # (T, C): lens covered
    joints = body17_positions(sampled)  # (T, 17, 3)
    thickness = joint_thickness(body)
    # The third stream (dark frames) leaves the first two as they were with two.
    rng_inject, rng_noise, rng_dark = (
        np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(3)
    )

    out = Path(out_dir)
    names = [c.name.replace("/", "-") for c in cameras]
    for name in names:
        (out / name).mkdir(parents=True, exist_ok=True)
    n_frames, n_cams = poses.shape[:2]
    images = np.zeros((n_cams, n_frames, model.height, model.width, 3), np.uint8)
    blocked = np.zeros((n_cams, n_frames))
    records: list[tuple] = []
    start = time.perf_counter()
    with BodyScene(body) as scene:
        renderer = FisheyeRenderer(scene, model)
        circle = renderer.maps.range_scale > 0
        for t in range(n_frames):  # rendering is inherently per frame
            scene.update(sampled, t)
            for c in range(n_cams):
                if inside[t, c]:
                    color = occlusion.dark_frame(model.height, model.width, rng_dark)
                    range_m = np.zeros((model.height, model.width), np.float32)
                    blocked[c, t] = 1.0
                else:
                    color, range_m = renderer.render(poses[t, c])
                    color, blocked[c, t] = occlusion.block_lens(color, range_m, circle)
                images[c, t] = color
                range_mm = np.clip(np.rint(range_m * 1000.0), 0, 65535).astype(np.uint16)
                cv2.imwrite(str(out / names[c] / f"{t:06d}_range.png"), range_mm)
                uv, in_image, joint_range = project_joints(
                    model, poses[t, c][None], joints[t][None]
                )
                vis = visibility(uv[0], in_image[0], joint_range[0], range_m, thickness)
                records.append((t, c, uv[0], in_image[0], vis & ~inside[t, c]))
    elapsed = time.perf_counter() - start

    truth = np.zeros((n_cams, n_frames), bool)
    for c in range(n_cams):
        images[c], truth[c], _ = bad_frames.inject(images[c], rng_inject, bad_frame_rate)
        for t in range(n_frames):
            cv2.imwrite(str(out / names[c] / f"{t:06d}.png"), images[c, t][..., ::-1])
    occluded = blocked >= occlusion.OCCLUDED_FRACTION  # (C, T)
    w2c = world_to_camera(poses)
    frames_json = []
    for t, c, uv, in_image, vis in records:
        conf = confidence(model, uv, vis)
        if detector_noise is not None:
            uv, detected, conf = detector_noise.apply(uv, vis, conf, rng_noise)
            in_image = in_image & detected
        frames_json.append(
            frame_record(
                names[c],
                model,
                t,
                t / rate_hz,
                w2c[t, c],
                joints[t],
                uv,
                in_image,
                vis,
                conf,
                bad_frame=bool(truth[c, t]),
                lens_blocked=blocked[c, t],
                occluded=bool(occluded[c, t]),
                mean_luminance=occlusion.mean_luminance(images[c, t], circle),
            )
        )
    flagged = np.stack([bad_frames.detect(images[c]) for c in range(n_cams)])
    # Occluded frames are dark for a reason the injected faults do not cover: the detector
    # is scored on the other frames only.
    clear = ~occluded
    # The data record depends on the seed alone (same seed => same bytes); the wall-clock
    # speed and the folder it was written to go in the returned summary only.
    recording = {
        "frames": int(n_frames),
        "cameras": names,
        "fps": rate_hz,
        "bad_frames": bad_frames.precision_recall(truth[clear], flagged[clear]),
        "occluded_frames": {name: int(occluded[c].sum()) for c, name in enumerate(names)},
        "seed": seed,
        "model": model.as_dict(),
    }
    (out / "keypoints.json").write_text(json.dumps({**recording, "records": frames_json}))
    summary = {
        **recording,
        "fps_rendered": n_frames * n_cams / max(elapsed, 1e-9),
        "out_dir": str(out),
    }
    if stitch:
        summary["stitched"] = _write_stitched(model, cameras, images, out)
    if video:
        tiled = np.concatenate(
            [np.concatenate(list(images[r : r + 2]), axis=2) for r in range(0, n_cams, 2)], axis=1
        )
        # Even sizes for H.264.
        imageio.mimwrite(
            out / "fisheye.mp4",
            tiled[:, : tiled.shape[1] // 2 * 2, : tiled.shape[2] // 2 * 2],
            fps=rate_hz,
            macro_block_size=1,
        )
        summary["video"] = str(out / "fisheye.mp4")
    return summary


def _write_stitched(
    model: FisheyeModel,
    cameras: Sequence[ControllerCamera],
    images: np.ndarray,
    out: Path,
) -> list[str]:
    """Each controller's two cameras stitched onto one cylinder (ControllerPose §4.2) per
    frame, from stitch parameters computed once per controller: ``stitched/<controller>/``."""
    folders = []
    by_controller: dict[str, list[int]] = {}
    for c, camera in enumerate(cameras):
        by_controller.setdefault(camera.controller, []).append(c)
    for controller, pair in by_controller.items():
        if len(pair) != 2:
            continue
        params = stitch_params(model, [cameras[c] for c in pair])
        folder = out / "stitched" / controller
        folder.mkdir(parents=True, exist_ok=True)
        for t in range(images.shape[1]):
            composite = params.stitch([images[c, t] for c in pair])
            cv2.imwrite(str(folder / f"{t:06d}.png"), composite[..., ::-1])
        folders.append(str(folder.relative_to(out)))
    return folders
