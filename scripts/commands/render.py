"""``avatarsim render MOTION --device ...``: what a device would record, written to a folder.

fisheye: the four controller cameras (PNG frames, 16-bit range in mm, keypoints JSON with the
camera model per frame, MP4). kinect-v2 / azure-kinect: 16-bit depth PNG in mm, body-index
PNG, skeleton JSON per frame, preview video.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape

from scripts.cli_common import (
    JsonOpt,
    SeedOpt,
    check_outputs,
    console,
    emit_json,
    load_motion_arg,
    user_errors,
)

DEVICES = ("fisheye", "kinect-v2", "azure-kinect", "azure-kinect-wfov-binned")
MAX_DURATION_S = 600.0  # seconds of motion rendered (about 30 frames per second of it)
SIZE_RANGE = (16, 4096)  # fisheye image side in pixels


def _pair(text: str | None, option: str, default: tuple, kind=float) -> tuple:
    """``"A,B"`` -> ``(A, B)`` of ``kind``; a clear error for anything else."""
    from avatar_models.errors import AvatarsimError

    if text is None:
        return default
    try:
        a, b = (kind(v) for v in text.split(","))
        if not all(math.isfinite(v) for v in (a, b)):
            raise ValueError
    except ValueError:
        raise AvatarsimError(f"{option} takes two numbers 'A,B', got {text!r}") from None
    return a, b


def register(app: typer.Typer) -> None:
    @app.command()
    @user_errors
    def render(
        motion: Annotated[str, typer.Argument(help="Motion file, or builtin:ACTIVITY.")],
        device: Annotated[str, typer.Option(help=f"One of: {', '.join(DEVICES)}.")] = "fisheye",
        out: Annotated[Path, typer.Option(help="Output folder.")] = Path("out/render"),
        duration_s: Annotated[
            float, typer.Option(help=f"Seconds of motion to record (at most {MAX_DURATION_S:g}).")
        ] = 2.0,
        fov: Annotated[
            str | None, typer.Option(help="fisheye: field of view 'H,V' in degrees (150,120).")
        ] = None,
        size: Annotated[
            str | None,
            typer.Option(
                help=f"fisheye: image size 'W,H' in pixels (640,480; {SIZE_RANGE[0]}-"
                f"{SIZE_RANGE[1]} each)."
            ),
        ] = None,
        unit: Annotated[str | None, typer.Option(help="File unit (see `info`).")] = None,
        seed: SeedOpt = 0,
        json_out: JsonOpt = None,
    ) -> None:
        """Images, depth, keypoints and a video that a device would record of MOTION."""
        from avatar_models.errors import AvatarsimError

        if device not in DEVICES:
            raise AvatarsimError(f"unknown device {device!r}; devices: {', '.join(DEVICES)}")
        if not 0 < duration_s <= MAX_DURATION_S:
            raise AvatarsimError(
                f"--duration-s must be above 0 and at most {MAX_DURATION_S:g}, got {duration_s}"
            )
        if device != "fisheye":
            given = [o for o, v in (("--fov", fov), ("--size", size)) if v is not None]
            if given:
                raise AvatarsimError(
                    f"{' and '.join(given)} set the fisheye camera; {device} has a fixed "
                    "field of view and image size"
                )
        fov_deg = _pair(fov, "--fov", (150, 120))
        size_px = _pair(size, "--size", (640, 480), int)
        if not all(0 < v < 180 for v in fov_deg):
            raise AvatarsimError(
                f"--fov: a FOV must be two angles in (0, 180) degrees, got {fov!r}"
            )
        lo, hi = SIZE_RANGE
        if not all(lo <= v <= hi for v in size_px):
            raise AvatarsimError(f"--size must be two sides of {lo}-{hi} pixels, got {size!r}")
        check_outputs(json_out=json_out, out=out)
        m = load_motion_arg(motion, unit, seed, duration_s)
        m = m[: max(2, int(round(duration_s * m.fps)) + 1)]
        t0 = time.perf_counter()
        if device == "fisheye":
            from render_cams.fisheye.model import FisheyeModel
            from render_cams.fisheye.sequence import render_fisheye_sequence

            model = FisheyeModel.from_fov(*fov_deg, *size_px)
            summary = render_fisheye_sequence(m, out, seed=seed, model=model)
        else:
            from render_cams.kinect.sequence import render_kinect_sequence

            summary = render_kinect_sequence(m, out, device=device, seed=seed)
        elapsed = time.perf_counter() - t0
        summary = dict(summary)
        summary.setdefault("fps_rendered", summary.get("frames", 0) / max(elapsed, 1e-9))
        console.print(
            escape(
                f"{device}: {summary.get('frames')} frames in {elapsed:.1f} s "
                f"({summary['fps_rendered']:.1f} frames/s) -> {out}/"
            )
        )
        emit_json(json_out, {"device": device, "out_dir": str(out), **summary})
