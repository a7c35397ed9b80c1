"""``avatarsim render MOTION --device ...``: what a device would record, written to a folder.

fisheye: the four controller cameras (PNG frames, 16-bit range in mm, keypoints JSON with the
camera model per frame, MP4). kinect-v2 / azure-kinect: 16-bit depth PNG in mm, body-index
PNG, skeleton JSON per frame, preview video.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import typer

from scripts.cli_common import JsonOpt, SeedOpt, console, emit_json, load_motion_arg, user_errors

DEVICES = ("fisheye", "kinect-v2", "azure-kinect", "azure-kinect-wfov-binned")


def _pair(text: str | None, option: str, default: tuple, kind=float) -> tuple:
    """``"A,B"`` -> ``(A, B)`` of ``kind``; a clear error for anything else."""
    from avatar_models.errors import AvatarsimError

    if text is None:
        return default
    try:
        a, b = (kind(v) for v in text.split(","))
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
        duration_s: Annotated[float, typer.Option(help="Seconds of motion to record.")] = 2.0,
        fov: Annotated[
            str | None, typer.Option(help="fisheye: field of view 'H,V' in degrees (150,120).")
        ] = None,
        size: Annotated[
            str | None, typer.Option(help="fisheye: image size 'W,H' in pixels (640,480).")
        ] = None,
        unit: Annotated[str | None, typer.Option(help="File unit (see `info`).")] = None,
        seed: SeedOpt = 0,
        json_out: JsonOpt = None,
    ) -> None:
        """Images, depth, keypoints and a video that a device would record of MOTION."""
        from avatar_models.errors import AvatarsimError

        if device not in DEVICES:
            raise AvatarsimError(f"unknown device {device!r}; devices: {', '.join(DEVICES)}")
        if not duration_s > 0:
            raise AvatarsimError(f"--duration-s must be positive, got {duration_s}")
        m = load_motion_arg(motion, unit, seed, duration_s)
        m = m[: max(2, int(round(duration_s * m.fps)) + 1)]
        t0 = time.perf_counter()
        if device == "fisheye":
            from render_cams.fisheye.model import FisheyeModel
            from render_cams.fisheye.sequence import render_fisheye_sequence

            model = FisheyeModel.from_fov(
                *_pair(fov, "--fov", (150, 120)), *_pair(size, "--size", (640, 480), int)
            )
            summary = render_fisheye_sequence(m, out, seed=seed, model=model)
        else:
            from render_cams.kinect.sequence import render_kinect_sequence

            summary = render_kinect_sequence(m, out, device=device, seed=seed)
        elapsed = time.perf_counter() - t0
        summary = dict(summary)
        summary.setdefault("fps_rendered", summary.get("frames", 0) / max(elapsed, 1e-9))
        console.print(
            f"{device}: {summary.get('frames')} frames in {elapsed:.1f} s "
            f"({summary['fps_rendered']:.1f} frames/s) -> {out}/"
        )
        emit_json(json_out, {"device": device, "out_dir": str(out), **summary})
