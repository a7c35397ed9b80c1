"""Pictures a person can look at, rendered headless with MuJoCo: a PNG strip and a GIF of the
ground truth, and a side-by-side GIF and strip of the ground truth next to each method."""

from __future__ import annotations

import cv2
import imageio.v3 as iio
import numpy as np

from avatarsim.avatar_models.fileio import write_atomic
from avatarsim.scripts.run_context import RunContext
from avatarsim.sim.humanoid import Humanoid
from avatarsim.sim.render import render_frames

METRICS: dict[str, str] = {}


def labelled(frames: np.ndarray, label: str) -> np.ndarray:
    """``frames (N, H, W, 3)`` with ``label`` written in the top-left corner."""
    out = frames.copy()
    for f in out:
        cv2.putText(
            f, label, (8, 22), cv2.FONT_HERSHEY_SIMPLEX, 0.6, (255, 255, 255), 2, cv2.LINE_AA
        )
    return out


def humanoid_frames(h: Humanoid, times_s: np.ndarray, width: int, height: int) -> np.ndarray:
    """``(N, H, W, 3)`` renders of ``h`` at ``times_s (N,)`` (nearest frames)."""
    ids = np.minimum(np.round(times_s * h.motion.fps).astype(int), h.qpos.shape[0] - 1)
    return render_frames(h.model, h.qpos, ids, width, height)


def png(image: np.ndarray) -> bytes:
    return iio.imwrite("<bytes>", image, extension=".png")


def gif(frames: np.ndarray, fps: float) -> bytes:
    return iio.imwrite("<bytes>", frames, extension=".gif", duration=1000.0 / fps, loop=0)


def run(ctx: RunContext) -> None:
    spec = ctx.scenario.report
    h = ctx.humanoid
    n = h.qpos.shape[0]
    last = min(n - 1, int(round(spec.strip_span_s * ctx.motion.fps)))
    strip_ids = np.linspace(0, last, spec.picture_frames).round().astype(int)
    strip = np.hstack(render_frames(h.model, h.qpos, strip_ids))
    ctx.output("strip_png", write_atomic(ctx.out_dir / "strip.png", png(strip)))
    gif_ids = np.arange(0, n, max(1, int(round(ctx.motion.fps / spec.gif_fps))))
    if spec.gif:
        frames = render_frames(h.model, h.qpos, gif_ids, width=240, height=300)
        ctx.output(
            "motion_gif", write_atomic(ctx.out_dir / "motion.gif", gif(frames, spec.gif_fps))
        )

    if not ctx.synthesised:
        return
    # Ground truth and every method side by side at the same times (methods run at 90 Hz,
    # the truth at its own rate).
    columns = {"ground truth": h} | ctx.synthesised
    span_s = min(c.motion.duration_s for c in columns.values())
    times_strip = np.linspace(0.0, min(span_s, spec.strip_span_s), 4)
    panels = [
        labelled(humanoid_frames(c, times_strip, 240, 300), name) for name, c in columns.items()
    ]
    grid = np.vstack([np.hstack(list(p)) for p in panels])
    ctx.output("compare_png", write_atomic(ctx.out_dir / "compare.png", png(grid)))
    if spec.gif:
        times = np.arange(0.0, span_s, 1.0 / spec.gif_fps)
        side = np.concatenate(
            [labelled(humanoid_frames(c, times, 240, 300), name) for name, c in columns.items()],
            axis=2,
        )
        ctx.output(
            "compare_gif", write_atomic(ctx.out_dir / "compare.gif", gif(side, spec.gif_fps))
        )
