"""A fisheye recording (:class:`~render_cams.fisheye.device.FisheyeRecording`) on disk.

Layout of ``out_dir``:

- ``<camera>/NNNNNN.png``: colour frames (``camera`` is e.g. ``left_controller-ring``);
- ``<camera>/NNNNNN_range.png``: 16-bit range along each pixel's ray in millimetres (0 = none);
- ``keypoints.json``: the recording's summary (seed, camera model...) and its frame records;
  no timings or absolute paths, so that the same motion and seed give the same bytes in any
  folder;
- ``stitched/<controller>/NNNNNN.png``: each controller's two cameras on one cylinder;
- ``fisheye.mp4``: the four cameras tiled 2x2, for a person to watch.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import cv2
import imageio.v2 as imageio
import numpy as np

from render_cams.fisheye.device import FisheyeRecording
from render_cams.fisheye.model import FisheyeModel
from render_cams.fisheye.rig import ControllerCamera
from render_cams.fisheye.stitch import stitch_params


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
        summary["stitched"] = _write_stitched(recording.model, recording.cameras, images, out)
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
