"""Pictures a person can look at: a PNG strip and a GIF of the humanoid, rendered headless."""

from __future__ import annotations

import imageio.v3 as iio
import numpy as np

from scripts.results import write_atomic
from scripts.run_context import RunContext
from sim.render import render_frames

METRICS: dict[str, str] = {}


def run(ctx: RunContext) -> None:
    spec = ctx.scenario.report
    n = ctx.qpos.shape[0]
    last = min(n - 1, int(round(spec.strip_span_s * ctx.motion.fps)))
    strip_ids = np.linspace(0, last, spec.picture_frames).round().astype(int)
    strip = np.hstack(render_frames(ctx.model, ctx.qpos, strip_ids))
    ctx.output(
        "strip_png",
        write_atomic(ctx.out_dir / "strip.png", iio.imwrite("<bytes>", strip, extension=".png")),
    )
    if spec.gif:
        step = max(1, int(round(ctx.motion.fps / spec.gif_fps)))
        frames = render_frames(ctx.model, ctx.qpos, np.arange(0, n, step), width=240, height=300)
        gif = iio.imwrite(
            "<bytes>", frames, extension=".gif", duration=1000.0 / spec.gif_fps, loop=0
        )
        ctx.output("motion_gif", write_atomic(ctx.out_dir / "motion.gif", gif))
