"""What a sample records of its window, one function per channel: each returns its arrays
(float32 for real values: training data, ~1e-7 relative error, half the size) and the JSON
that describes them. All take the window's humanoid (:func:`sim.humanoid.humanoid_for`),
whose motion and body every channel shares, and a channel seed.

- :func:`vr_channel`: headset + controllers (+ trackers) at 90 Hz with the validity mask.
- :func:`fisheye_channel`: the controller cameras' body17 keypoints, *projected*: the
  cameras' poses and lens model are the :class:`render_cams.fisheye.device.FisheyeRig`'s,
  but no image is rendered, so ``in_view`` ("in the image, the lens not inside the body and
  nothing in the way") is occlusion-tested by a ray test against the body's segments
  (:func:`render_cams.fisheye.line_of_sight.occluded`) instead of a range image. ``fisheye_uv``
  and ``fisheye_conf`` are what the ``"error-model"`` detector reports
  (:class:`render_cams.fisheye.detector.ErrorModelDetector`, a fast approximation of a 2D
  detector from the exact projections, seeded; its confidence does not encode the error it
  draws): the exact projections are ``fisheye_uv_projected``.
- :func:`kinect_channel`: the Kinect skeleton with tracking states (tracked on the rendered
  depth by default).
- :func:`fisheye_image_channel` and the Kinect's depth and body-part labels
  (:func:`kinect_channel`): rendered images of every ``image_stride``-th camera frame, one
  encoded file per camera and frame (JPEG or PNG RGB; 16-bit PNG depth in millimetres, 8-bit
  PNG part labels), as WebDataset stores images; their
  frame indices and the cameras' intrinsics and extrinsics are in arrays and JSON beside
  them.
- :func:`physics_channel`: per-frame foot contact, floor penetration and foot skate from
  :func:`sim.plausibility.check_humanoid`.
"""

from __future__ import annotations

from dataclasses import asdict, replace
from typing import Any

import cv2
import numpy as np

from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.render_cams.device import motion_at_rate
from avatarsim.render_cams.fisheye.detector import ErrorModelDetector
from avatarsim.render_cams.fisheye.device import CAMERA_RATE_HZ, FisheyeRig
from avatarsim.render_cams.fisheye.keypoints import confidence, project_joints, world_to_camera
from avatarsim.render_cams.fisheye.line_of_sight import occluded
from avatarsim.render_cams.fisheye.pose2d import controller_views
from avatarsim.render_cams.fisheye.rig import camera_poses, controller_cameras, inside_body
from avatarsim.render_cams.kinect import Kinect, default_sensor_pose, get_sensor
from avatarsim.render_cams.kinect.parts import PART_NAMES
from avatarsim.render_cams.kinect.placement import orbit, performer_target
from avatarsim.render_cams.vr import FULL_BODY, HEADSET_AND_CONTROLLERS, VRSetup
from avatarsim.render_cams.vr.noise import REALISTIC_NOISE
from avatarsim.scripts.dataset.config import DeviceSetConfig
from avatarsim.sim.humanoid import Humanoid
from avatarsim.sim.plausibility import check_humanoid

Channel = tuple[dict[str, np.ndarray | bytes], dict[str, Any]]  # bytes: an encoded image
CM = 0.01  # the checks report centimetres; datasets store metres
IMAGE_SUFFIX = {"jpeg": ".jpg", "png": ".png"}
IMAGE_PARAMS = {"jpeg": [cv2.IMWRITE_JPEG_QUALITY, 90], "png": [cv2.IMWRITE_PNG_COMPRESSION, 3]}


def f32(values: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(values, dtype=np.float32)


def vr_channel(humanoid: Humanoid, devices: DeviceSetConfig, seed: int) -> Channel:
    """``vr_time`` (Tv,), ``vr_pos`` (Tv, D, 3), ``vr_quat`` (Tv, D, 4) wxyz, ``vr_valid``
    (Tv, D) bool."""
    setup = VRSetup(
        devices=FULL_BODY if devices.trackers else HEADSET_AND_CONTROLLERS,
        noise=REALISTIC_NOISE if devices.vr_noise == "realistic" else (),
    )
    stream = setup.sample(humanoid.motion, seed=seed)
    arrays = {
        "vr_time": f32(stream.timestamps),
        "vr_pos": f32(stream.positions),
        "vr_quat": f32(stream.quaternions),
        "vr_valid": np.ascontiguousarray(stream.valid, dtype=bool),
    }
    meta = {
        "rate_hz": setup.rate_hz,
        "devices": list(stream.device_names),
        "noise": devices.vr_noise,
        "seed": seed,
    }
    return arrays, meta


def fisheye_channel(humanoid: Humanoid, seed: int) -> Channel:
    """``fisheye_uv`` (Tc, C, 17, 2) detected pixels ((0, 0) where not detected),
    ``fisheye_conf`` (Tc, C, 17) detector confidence (0 where not detected),
    ``fisheye_detected`` (Tc, C, 17) bool, ``fisheye_uv_projected`` (Tc, C, 17, 2) exact
    pixels, ``fisheye_in_view`` (Tc, C, 17) bool, ``fisheye_lens_covered`` (Tc, C) bool,
    ``fisheye_w2c`` (Tc, C, 4, 4) world-to-camera (OpenCV axes); intrinsics and the detector
    model in the JSON. Projected, not rendered (module docstring).

    Also the 2D poses ControllerPose lifts (§4.3; :func:`render_cams.fisheye.pose2d.
    controller_views`): per controller, the detector's report on its composite and on the
    torso-normal view built from that report, as ``V`` = 2 x controllers views in the order
    of ``meta["views"]`` (``"<controller>/composite"``, ``"<controller>/torso"``):
    ``fisheye_view_uv`` (Tc, V, 17, 2) pixels of that view ((0, 0) where not detected),
    ``fisheye_view_conf`` (Tc, V, 17), ``fisheye_view_detected`` (Tc, V, 17) bool. A camera
    whose lens the body covers is left out of its composite (no image filter runs on
    projected keypoints). Drawn from their own generator, so the per-camera detections
    above are those of a dataset without views."""
    rig = FisheyeRig()
    sampled = motion_at_rate(humanoid.motion, rig.rate_hz)
    cameras = controller_cameras(rig.controllers, rig.mount)
    poses = camera_poses(sampled, cameras)  # (Tc, C, 4, 4)
    pose = sampled.fk()
    covered = inside_body(humanoid.body, *pose, poses[..., :3, 3])  # (Tc, C)
    joints = body17_positions(sampled)  # (Tc, 17, 3)
    n_frames, n_cams = poses.shape[:2]
    uv, in_image, _ = project_joints(
        rig.model, poses.reshape(-1, 4, 4), np.repeat(joints, n_cams, axis=0)
    )
    uv = uv.reshape(n_frames, n_cams, -1, 2)
    in_image = in_image.reshape(n_frames, n_cams, -1) & ~covered[..., None]
    hidden = np.stack(
        [occluded(humanoid.body, *pose, poses[:, c, :3, 3], joints) for c in range(n_cams)],
        axis=1,
    )  # (Tc, C, 17)
    in_view = in_image & ~hidden
    detector = ErrorModelDetector()
    score = confidence(rig.model, uv, in_view)
    detection = detector.detect_projected(uv, in_image, in_view, score, np.random.default_rng(seed))
    views = controller_views(
        rig.model, cameras, uv, in_image, in_view, score, ~covered, detector,
        np.random.default_rng([seed, 1]),
    )  # fmt: skip
    view_names = [f"{c}/{kind}" for c in views for kind in ("composite", "torso")]
    reports = [d for v in views.values() for d in (v.composite_detection, v.torso_detection)]
    arrays = {
        "fisheye_uv": f32(detection.uv),
        "fisheye_conf": f32(detection.confidence),
        "fisheye_detected": detection.detected,
        "fisheye_uv_projected": f32(uv),
        "fisheye_in_view": in_view,
        "fisheye_lens_covered": np.ascontiguousarray(covered, dtype=bool),
        "fisheye_w2c": f32(world_to_camera(poses)),
        "fisheye_view_uv": f32(np.stack([d.uv for d in reports], axis=1)),
        "fisheye_view_conf": f32(np.stack([d.confidence for d in reports], axis=1)),
        "fisheye_view_detected": np.stack([d.detected for d in reports], axis=1),
    }
    meta = {
        "rate_hz": rig.rate_hz,
        "cameras": [c.name for c in cameras],
        "model": rig.model.as_dict(),
        "keypoints": "projected (no images rendered; in_view occlusion-tested by a ray test "
        'against the body), then detected by the "error-model" detector (a fast approximation '
        "of a 2D detector; its confidence does not encode the drawn error)",
        "detector": {"name": detector.name, "label": detector.label, **asdict(detector)},
        "seed": seed,
        "views": view_names,
        "view_sizes": {
            c: [v.params.cylinder.width, v.params.cylinder.height] for c, v in views.items()
        },
    }
    return arrays, meta


def kinect_channel(humanoid: Humanoid, devices: DeviceSetConfig, seed: int) -> Channel:
    """``kinect_pos`` (Tk, J, 3) world metres (meaningless where not tracked),
    ``kinect_quat`` (Tk, J, 4) wxyz, ``kinect_state`` (Tk, J) int8 (0 not tracked,
    1 inferred, 2 tracked) of the ``devices.kinect`` sensor's ``kinect_skeleton`` (tracked on
    the rendered depth, or ``"oracle-noise"``: not a sensor, the JSON's ``skeleton_note``
    says so), the sensor set up in front of the performer at ``kinect_height_m`` and turned
    ``kinect_yaw_deg`` about them; sensor intrinsics and pose in the JSON. With
    ``kinect_depth``, also the depth of every ``image_stride``-th frame, with the sensor's
    depth noise: ``kinect_depth_frames`` (N,) int frame indices into Tk and
    ``kinect_depth.{n:04d}.png`` (H, W) uint16 millimetres (0: no reading), rendered with the
    skeleton's seed; with ``kinect_parts``, ``kinect_parts.{n:04d}.png`` (H, W) uint8, the
    body-part label of each depth pixel (:mod:`render_cams.kinect.parts`: part ``k + 1`` is
    body17 joint ``k``, 0 no body), aligned with that depth image."""
    motion = humanoid.motion
    sensor = get_sensor(devices.kinect)
    at_rate = motion_at_rate(motion, sensor.rate_hz)
    front = default_sensor_pose(at_rate, sensor, devices.kinect_height_m)
    pose = orbit(front, performer_target(motion), np.radians(devices.kinect_yaw_deg))
    kinect = Kinect(sensor, sensor_pose=pose, skeleton=devices.kinect_skeleton)
    recording = kinect.sample(motion, seed=seed, body=humanoid.body)
    skeleton = recording.skeleton
    arrays: dict[str, Any] = {
        "kinect_pos": f32(skeleton.positions),
        "kinect_quat": f32(skeleton.orientations),
        "kinect_state": np.ascontiguousarray(skeleton.states, dtype=np.int8),
    }
    meta = dict(recording.record)
    meta["yaw_deg"] = devices.kinect_yaw_deg
    if devices.kinect_depth:
        stride = devices.image_stride
        frames = recording.frames
        strided = replace(frames, motion=frames.motion[::stride])
        arrays["kinect_depth_frames"] = np.arange(len(strided), dtype=np.int32) * stride
        for n, frame in enumerate(strided):
            arrays[f"kinect_depth.{n:04d}.png"] = encode_image(frame.depth_mm, "png")
            if devices.kinect_parts:
                arrays[f"kinect_parts.{n:04d}.png"] = encode_image(frame.parts, "png")
        meta["depth"] = {"format": "png16", "unit": "mm", "stride": stride}
        if devices.kinect_parts:
            meta["parts"] = {"format": "png8", "names": ["none", *PART_NAMES], "stride": stride}
    return arrays, meta


def encode_image(image: np.ndarray, fmt: str) -> bytes:
    """``image`` (H, W, 3) uint8 RGB or (H, W) uint16 as a ``"jpeg"`` or ``"png"`` file
    (OpenCV's encoders: the same pixels always give the same bytes)."""
    pixels = image[..., ::-1] if image.ndim == 3 else image  # OpenCV writes BGR
    ok, data = cv2.imencode(IMAGE_SUFFIX[fmt], np.ascontiguousarray(pixels), IMAGE_PARAMS[fmt])
    if not ok:
        raise ValueError(f"cannot encode a {image.dtype} {image.shape} image as {fmt}")
    return data.tobytes()


def fisheye_image_channel(humanoid: Humanoid, devices: DeviceSetConfig, seed: int) -> Channel:
    """``fisheye_image_frames`` (N,) int camera-frame indices (into ``fisheye_uv``'s Tc) and
    ``fisheye_image.{camera}.{n:04d}.jpg|png`` (h, w, 3) RGB per camera and rendered frame,
    as :class:`~render_cams.fisheye.device.FisheyeRig` records them (bad frames injected,
    dark when the lens is covered) at ``image_scale``; the scaled intrinsics in the JSON."""
    rig = FisheyeRig(scale=devices.image_scale, rate_hz=CAMERA_RATE_HZ / devices.image_stride)
    recording = rig.sample(humanoid.motion, seed=seed, body=humanoid.body)
    n_frames = recording.images.shape[1]
    arrays: dict[str, Any] = {
        "fisheye_image_frames": np.arange(n_frames, dtype=np.int32) * devices.image_stride
    }
    for c, name in enumerate(recording.names):
        for n in range(n_frames):
            entry = f"fisheye_image.{name}.{n:04d}{IMAGE_SUFFIX[devices.fisheye_images]}"
            arrays[entry] = encode_image(recording.images[c, n], devices.fisheye_images)
    meta = {
        "format": devices.fisheye_images,
        "cameras": list(recording.names),
        "stride": devices.image_stride,
        "model": recording.model.as_dict(),
        "bad_frames": recording.summary["bad_frames"],
        "seed": seed,
    }
    return arrays, meta


def physics_channel(humanoid: Humanoid) -> Channel:
    """``contact`` (T, 2) bool (left, right foot), ``penetration_m`` (T,), ``skate_m_s``
    (T, 2) (left, right), at the window's frames."""
    columns = check_humanoid(humanoid).per_frame()
    arrays = {
        "contact": np.stack([columns["contact_left"], columns["contact_right"]], 1) > 0,
        "penetration_m": f32(columns["penetration_cm"] * CM),
        "skate_m_s": f32(
            np.stack([columns["skate_left_cm_s"], columns["skate_right_cm_s"]], 1) * CM
        ),
    }
    return arrays, {"source": "avatarsim.sim.plausibility.check_humanoid", "units": "m, m/s"}
