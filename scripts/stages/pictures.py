"""Pictures a person can look at, rendered headless with MuJoCo: a PNG strip and a GIF of the
ground truth, and a side-by-side GIF and strip of the ground truth next to each method."""

from __future__ import annotations

import cv2
import imageio.v3 as iio
import mujoco
import numpy as np

from avatar_models.body import build_body
from avatar_models.motion import Motion
from scripts.results import write_atomic
from scripts.run_context import RunContext
from sim.render import render_frames

METRICS: dict[str, str] = {}


def labelled(frames: np.ndarray, label: str) -> np.ndarray:
    """``frames (N, H, W, 3)`` with ``label`` written in the top-left corner."""
    out = frames.copy()
    for f in out:
        cv2.putText(
            f, label, (8, 22), cv2.FONT_HERSHEY_SIMPLEX, 0.6, (255, 255, 255), 2, cv2.LINE_AA
        )
    return out


def motion_frames(motion: Motion, frame_ids: np.ndarray, width: int, height: int) -> np.ndarray:
    body = build_body(motion.skeleton)
    model = mujoco.MjModel.from_xml_string(body.to_mjcf())
    return render_frames(model, body.qpos_from_motion(motion), frame_ids, width, height)


def png(image: np.ndarray) -> bytes:
    return iio.imwrite("<bytes>", image, extension=".png")


def gif(frames: np.ndarray, fps: float) -> bytes:
    return iio.imwrite("<bytes>", frames, extension=".gif", duration=1000.0 / fps, loop=0)


def run(ctx: RunContext) -> None:
    spec = ctx.scenario.report
    n = ctx.qpos.shape[0]
    last = min(n - 1, int(round(spec.strip_span_s * ctx.motion.fps)))
    strip_ids = np.linspace(0, last, spec.picture_frames).round().astype(int)
    strip = np.hstack(render_frames(ctx.model, ctx.qpos, strip_ids))
    ctx.output("strip_png", write_atomic(ctx.out_dir / "strip.png", png(strip)))
    gif_ids = np.arange(0, n, max(1, int(round(ctx.motion.fps / spec.gif_fps))))
    if spec.gif:
        frames = render_frames(ctx.model, ctx.qpos, gif_ids, width=240, height=300)
        ctx.output(
            "motion_gif", write_atomic(ctx.out_dir / "motion.gif", gif(frames, spec.gif_fps))
        )

    synthesised: dict[str, Motion] = ctx.artifacts.get("synthesised", {})
    if not synthesised:
        return
    # Ground truth and every method side by side, frame for frame (all at the truth's fps
    # here: methods run at 90 Hz, the built-in truth too; a file's truth is resampled).
    columns = {"ground truth": ctx.motion.resample(90.0)} | synthesised
    rows = min(m.n_frames for m in columns.values())
    ids_strip = (
        np.linspace(0, min(rows - 1, int(round(spec.strip_span_s * 90))), 4).round().astype(int)
    )
    panels = [labelled(motion_frames(m, ids_strip, 240, 300), name) for name, m in columns.items()]
    grid = np.vstack([np.hstack(list(p)) for p in panels])
    ctx.output("compare_png", write_atomic(ctx.out_dir / "compare.png", png(grid)))
    if spec.gif:
        ids = np.arange(0, rows, max(1, int(round(90.0 / spec.gif_fps))))
        side = np.concatenate(
            [labelled(motion_frames(m, ids, 240, 300), name) for name, m in columns.items()], axis=2
        )
        ctx.output(
            "compare_gif", write_atomic(ctx.out_dir / "compare.gif", gif(side, spec.gif_fps))
        )
