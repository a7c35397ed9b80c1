"""A fisheye recording (:class:`~render_cams.fisheye.device.FisheyeRecording`) on disk.

Layout of ``out_dir``:

- ``<camera>/NNNNNN.png``: colour frames (``camera`` is e.g. ``left_controller-ring``);
- ``<camera>/NNNNNN_range.png``: 16-bit range along each pixel's ray in millimetres (0 = none);
- ``keypoints.json``: the recording's summary (seed, camera model...) and its frame records;
  no timings or absolute paths, so that the same motion and seed give the same bytes in any
  folder;
- ``stitched/<controller>/NNNNNN.png``: each controller's two cameras on one cylinder, from
  the frames the image filter kept (a dropped frame leaves its camera's part black, both
  dropped a black composite);
- ``torso/<controller>/NNNNNN.png``: the torso-normal view of that composite, where the
  detector reported both shoulders and hips;
- ``views.json``: per controller and frame, the detector's keypoints on the composite and in
  the torso view (:mod:`render_cams.fisheye.pose2d`), with the exact ones;
- ``fisheye.mp4``: the four cameras tiled 2x2, for a person to watch.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import cv2
import imageio.v2 as imageio
import numpy as np

from avatarsim.render_cams.fisheye.device import FisheyeRecording
from avatarsim.render_cams.fisheye.pose2d import ControllerPose2D
from avatarsim.render_cams.fisheye.records import detection_fields
from avatarsim.render_cams.fisheye.rig import camera_pairs
from avatarsim.render_cams.fisheye.stitch import stitch_params


def write_fisheye_recording(
    recording: FisheyeRecording, out_dir: str | Path, video: bool = True, stitch: bool = True
) -> dict[str, Any]:
    """Write ``recording`` into ``out_dir`` (created); return its summary plus
    ``fps_rendered``, ``out_dir`` and, when written, ``stitched`` folders and ``video``."""
    out = Path(out_dir)
    images = recording.images
    for c, name in enumerate(recording.names):
        (out / name).mkdir(parents=True, exist_ok=True)
        for t in range(images.shape[1]):
            cv2.imwrite(str(out / name / f"{t:06d}_range.png"), recording.range_mm[c, t])
            cv2.imwrite(str(out / name / f"{t:06d}.png"), images[c, t][..., ::-1])
    keypoints = {**recording.summary, "records": recording.records}
    (out / "keypoints.json").write_text(json.dumps(keypoints))
    summary = {
        **recording.summary,
        "fps_rendered": recording.fps_rendered,
        "out_dir": str(out),
    }
    if stitch:
        summary["stitched"] = _write_stitched(recording, out)
        (out / "views.json").write_text(json.dumps(views_json(recording.views)))
    if video:
        n_cams = images.shape[0]
        tiled = np.concatenate(
            [np.concatenate(list(images[r : r + 2]), axis=2) for r in range(0, n_cams, 2)], axis=1
        )
        # Even sizes for H.264.
        imageio.mimwrite(
            out / "fisheye.mp4",
            tiled[:, : tiled.shape[1] // 2 * 2, : tiled.shape[2] // 2 * 2],
            fps=recording.summary["fps"],
            macro_block_size=1,
        )
        summary["video"] = str(out / "fisheye.mp4")
    return summary


def _write_stitched(recording: FisheyeRecording, out: Path) -> list[str]:
    """Each controller's two cameras stitched onto one cylinder (ControllerPose §4.2) per
    frame from the frames the filter kept, with stitch parameters computed once per
    controller: ``stitched/<controller>/``; and its torso-normal views: ``torso/<controller>/``."""
    folders = []
    cameras, images = recording.cameras, recording.images
    for controller, pair in camera_pairs(cameras).items():
        view = recording.views.get(controller)
        params = (
            stitch_params(recording.model, [cameras[c] for c in pair])
            if view is None
            else view.params
        )
        folder = out / "stitched" / controller
        folder.mkdir(parents=True, exist_ok=True)
        if view is not None:
            (out / "torso" / controller).mkdir(parents=True, exist_ok=True)
        for t in range(images.shape[1]):
            usable = ~recording.filtered[pair, t]
            composite = params.stitch([images[c, t] for c in pair], usable)
            cv2.imwrite(str(folder / f"{t:06d}.png"), composite[..., ::-1])
            if view is not None and view.torso.valid[t]:
                warped = cv2.warpPerspective(
                    composite, view.torso.H[t], (composite.shape[1], composite.shape[0])
                )
                cv2.imwrite(str(out / "torso" / controller / f"{t:06d}.png"), warped[..., ::-1])
        folders.append(str(folder.relative_to(out)))
    return folders


def views_json(views: dict[str, ControllerPose2D]) -> dict[str, Any]:
    """JSON-ready composite and torso-view keypoints: ``{controller: [per frame {"composite":
    {exact_px, in_image, detected_px, detected, detected_confidence}, "torso": {H, ...}}]}``."""
    out = {}
    for controller, v in views.items():
        frames = []
        for t in range(v.composite.uv.shape[0]):
            frames.append(
                {
                    "composite": {
                        "exact_px": np.round(np.nan_to_num(v.composite.uv[t]), 4).tolist(),
                        "in_image": v.composite.in_image[t].tolist(),
                        **detection_fields(
                            v.composite_detection.uv[t],
                            v.composite_detection.detected[t],
                            v.composite_detection.confidence[t],
                        ),
                    },
                    "torso": {
                        "valid": bool(v.torso.valid[t]),
                        "H": np.round(v.torso.H[t], 8).tolist(),
                        "exact_px": np.round(np.nan_to_num(v.torso_uv[t]), 4).tolist(),
                        **detection_fields(
                            v.torso_detection.uv[t],
                            v.torso_detection.detected[t],
                            v.torso_detection.confidence[t],
                        ),
                    },
                }
            )
        out[controller] = frames
    return out
