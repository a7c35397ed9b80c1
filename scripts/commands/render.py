"""``avatarsim render DEVICE MOTION``: what a device would record, written to a folder.

``render fisheye``: the four controller cameras (PNG frames, 16-bit range in mm, keypoints
JSON with the camera model per frame, MP4). ``render kinect-v2`` / ``azure-kinect`` /
``azure-kinect-wfov-binned``: 16-bit depth PNG in mm, body-index PNG, skeleton JSON per frame,
preview video. Each has only its own device's options (another's exits 2, "no such option").

The frame range is ``--start`` to ``--end`` seconds of the clip (``--end end``: to its end), or
``--duration-s`` seconds from ``--start`` (default 2 s, cut at the clip's end). The old
spelling ``render MOTION --device DEVICE`` runs the same with a deprecation line.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.markup import escape

from avatarsim.scripts.cli_common import (
    JsonOpt,
    KinectSkeletonOpt,
    SeedOpt,
    check_outputs,
    console,
    emit_json,
    load_motion_arg,
    user_errors,
)

if TYPE_CHECKING:  # imported where used (keeps `--help` fast)
    from avatarsim.sim.humanoid import Humanoid

KINECT_DEVICES = ("kinect-v2", "azure-kinect", "azure-kinect-wfov-binned")
DEFAULT_DURATION_S = 2.0
MAX_DURATION_S = 600.0  # seconds of motion rendered (about 30 frames per second of it)
SIZE_RANGE = (16, 4096)  # fisheye image side in pixels


def _numbers(text: str | None, option: str, n: int, kind=float) -> tuple | None:
    """``"A,B[,C]"`` -> ``n`` finite numbers of ``kind``; a clear error for anything else."""
    from avatarsim.avatar_models.errors import AvatarsimError

    if text is None:
        return None
    try:
        values = tuple(kind(v) for v in text.split(","))
    except ValueError:
        values = ()
    if len(values) != n or not all(math.isfinite(v) for v in values):
        words = {2: "two numbers 'A,B'", 3: "three numbers 'X,Y,Z'"}[n]
        raise AvatarsimError(f"{option} takes {words}, got {text!r}")
    return values


def _rad(degrees: float) -> float:
    """Degrees (CLI) to radians, refusing NaN and infinities."""
    from avatarsim.avatar_models.errors import AvatarsimError

    if not math.isfinite(degrees):
        raise AvatarsimError(f"angles must be finite numbers of degrees, got {degrees}")
    return math.radians(degrees)


def _pair(text: str | None, option: str, default: tuple, kind=float) -> tuple:
    """``"A,B"`` -> ``(A, B)`` of ``kind``; a clear error for anything else."""
    return _numbers(text, option, 2, kind) or default


def _parse_range(start_s: float, end: str | None) -> float | str | None:
    """``--end`` as seconds after a valid ``--start``, ``"end"``, or None (checked before any
    motion is loaded)."""
    from avatarsim.avatar_models.errors import AvatarsimError

    if not (math.isfinite(start_s) and start_s >= 0):
        raise AvatarsimError(f"--start must be a non-negative number of seconds, got {start_s}")
    if end is None or end == "end":
        return end
    try:
        end_s = float(end)
    except ValueError:
        raise AvatarsimError(f"--end takes seconds or 'end', got {end!r}") from None
    if not (math.isfinite(end_s) and end_s > start_s):
        raise AvatarsimError(f"--end must be after --start ({start_s:g} s), got {end!r}")
    return end_s


def _frame_range(
    start_s: float, end: float | str | None, duration_s: float | None, clip_s: float
) -> tuple[float, float]:
    """The ``(start, end)`` seconds to render of a clip of ``clip_s`` seconds."""
    from avatarsim.avatar_models.errors import AvatarsimError

    if start_s >= clip_s:
        raise AvatarsimError(f"--start {start_s:g} s is past the clip's end ({clip_s:.3f} s)")
    if end is None:
        return start_s, min(start_s + (duration_s or DEFAULT_DURATION_S), clip_s)
    if end == "end":
        return start_s, clip_s
    if end > clip_s + 1e-6:
        raise AvatarsimError(
            f"--end {end:g} s is past the clip's end ({clip_s:.3f} s); use --end end"
        )
    return start_s, float(end)


def _fisheye_rig(
    fov: str | None,
    size: str | None,
    ring_offset: str | None,
    grip_offset: str | None,
    ring_pitch: float | None,
    grip_pitch: float | None,
):
    """The ``FisheyeRig`` the fisheye options describe (checked before any motion loads)."""
    from avatarsim.avatar_models.errors import AvatarsimError
    from avatarsim.render_cams.fisheye.device import FisheyeRig
    from avatarsim.render_cams.fisheye.model import FisheyeModel
    from avatarsim.render_cams.fisheye.rig import Mount

    fov_deg = _pair(fov, "--fov", (150, 120))
    size_px = _pair(size, "--size", (640, 480), int)
    if not all(0 < v < 180 for v in fov_deg):
        raise AvatarsimError(f"--fov: a FOV must be two angles in (0, 180) degrees, got {fov!r}")
    lo, hi = SIZE_RANGE
    if not all(lo <= v <= hi for v in size_px):
        raise AvatarsimError(f"--size must be two sides of {lo}-{hi} pixels, got {size!r}")
    default = Mount()
    mount = Mount(
        ring_offset_m=_numbers(ring_offset, "--ring-offset", 3) or default.ring_offset_m,
        grip_offset_m=_numbers(grip_offset, "--grip-offset", 3) or default.grip_offset_m,
        ring_pitch_rad=default.ring_pitch_rad if ring_pitch is None else _rad(ring_pitch),
        grip_pitch_rad=default.grip_pitch_rad if grip_pitch is None else _rad(grip_pitch),
    )
    return FisheyeRig(model=FisheyeModel.from_fov(*fov_deg, *size_px), mount=mount)


def _kinect_placement(
    sensor_pos: str | None,
    sensor_yaw: float | None,
    sensor_pitch: float | None,
    sensor_look_at: str | None,
    sensor_height: float | None,
) -> tuple[tuple | None, Any, float]:
    """``(position, camera_to_world, height)`` from the Kinect options: the pose is None for
    the automatic set-up (at ``height``) and for a position aimed at the performer (then
    ``position`` is set; the pose follows from the motion)."""
    from avatarsim.render_cams.kinect.placement import (
        DEFAULT_HEIGHT_M,
        KinectPlacementError,
        look_at,
        yaw_pitch_pose,
    )

    aims = {"--sensor-yaw": sensor_yaw, "--sensor-pitch": sensor_pitch}
    if sensor_pos is None:
        needs = [
            n for n, v in {**aims, "--sensor-look-at": sensor_look_at}.items() if v is not None
        ]
        if needs:
            raise KinectPlacementError(
                f"{', '.join(needs)} need --sensor-pos (where the sensor stands)"
            )
    elif sensor_height is not None:
        raise KinectPlacementError(
            "give --sensor-pos (its z is the height) or --sensor-height, not both"
        )
    if sensor_look_at is not None and any(v is not None for v in aims.values()):
        raise KinectPlacementError("give --sensor-look-at or --sensor-yaw/--sensor-pitch, not both")
    pos_xyz = _numbers(sensor_pos, "--sensor-pos", 3)
    look_xyz = _numbers(sensor_look_at, "--sensor-look-at", 3)
    height = DEFAULT_HEIGHT_M if sensor_height is None else sensor_height
    if pos_xyz is not None and pos_xyz[2] < 0:
        raise KinectPlacementError(f"--sensor-pos z = {pos_xyz[2]} m is below the floor")
    if not (math.isfinite(height) and 0.0 <= height <= 3.0):
        raise KinectPlacementError(f"--sensor-height must be in [0, 3] m, got {height}")
    pose = None
    if sensor_yaw is not None or sensor_pitch is not None:
        pose = yaw_pitch_pose(pos_xyz, _rad(sensor_yaw or 0.0), _rad(sensor_pitch or 0.0))
    elif look_xyz is not None:
        pose = look_at(pos_xyz, look_xyz)
    return pos_xyz, pose, height


def _render(
    device: str,
    record: Callable[[Humanoid, Path], dict],
    motion: str,
    out: Path,
    duration_s: float | None,
    start: float,
    end: str | None,
    unit: str | None,
    seed: int,
    json_out: Path | None,
) -> None:
    """Check the frame range and outputs, load the motion, ``record(humanoid, out)`` it and
    report (the device's own options were checked before this)."""
    from avatarsim.avatar_models.errors import AvatarsimError

    if duration_s is not None and end is not None:
        raise AvatarsimError("give --end or --duration-s, not both")
    if duration_s is not None and not 0 < duration_s <= MAX_DURATION_S:
        raise AvatarsimError(
            f"--duration-s must be above 0 and at most {MAX_DURATION_S:g}, got {duration_s}"
        )
    end_at = _parse_range(start, end)
    if isinstance(end_at, float) and end_at - start > MAX_DURATION_S:
        raise AvatarsimError(f"--start to --end spans more than {MAX_DURATION_S:g} s")
    check_outputs(json_out=json_out, out=out)
    # A built-in motion is generated long enough for the range asked.
    generate_s = end_at if isinstance(end_at, float) else None
    generate_s = generate_s or start + (duration_s or DEFAULT_DURATION_S)
    m = load_motion_arg(motion, unit, seed, generate_s)
    start_s, end_s = _frame_range(start, end_at, duration_s, m.duration_s)
    first = int(round(start_s * m.fps))
    m = m[first : max(first + 2, int(round(end_s * m.fps)) + 1)]

    # The humanoid for this motion, built once and passed to the device (a foreign rig,
    # e.g. Bandai's, is retargeted onto it).
    from avatarsim.sim.humanoid import humanoid_for

    humanoid = humanoid_for(m)
    t0 = time.perf_counter()
    summary = dict(record(humanoid, out))
    elapsed = time.perf_counter() - t0
    summary.setdefault("fps_rendered", summary.get("frames", 0) / max(elapsed, 1e-9))
    summary["start_s"], summary["end_s"] = round(start_s, 6), round(end_s, 6)
    console.print(
        escape(
            f"{device}: {summary.get('frames')} frames ({start_s:.2f}-{end_s:.2f} s) in "
            f"{elapsed:.1f} s ({summary['fps_rendered']:.1f} frames/s) -> {out}/"
        )
    )
    emit_json(json_out, {"device": device, "out_dir": str(out), **summary})


def _old_render(args: list[str], commands) -> tuple[list[str], str] | None:
    """``render MOTION [--device D] ...`` -> ``render D MOTION ...`` (D: fisheye when absent)."""
    from avatarsim.scripts.cli_legacy import is_new_spelling

    if is_new_spelling(args, commands):
        return None
    device, rest, k = "fisheye", [], 0
    while k < len(args):
        if args[k] == "--device" and k + 1 < len(args):
            device, k = args[k + 1], k + 2
            continue
        if args[k].startswith("--device="):
            device = args[k].split("=", 1)[1]
        else:
            rest.append(args[k])
        k += 1
    return [device, *rest], f"render MOTION --device {device}: use render {device} MOTION"


MotionArg = Annotated[str, typer.Argument(help="Motion file, or builtin:ACTIVITY.")]
OutOpt = Annotated[Path, typer.Option(help="Output folder.")]
DurationOpt = Annotated[
    float | None,
    typer.Option(help="Seconds to record from --start (default 2, cut at the clip's end)."),
]
StartOpt = Annotated[float, typer.Option(help="First second of the clip to record.")]
EndOpt = Annotated[
    str | None, typer.Option(help="Last second of the clip to record, or 'end' (the whole clip).")
]
UnitOpt = Annotated[str | None, typer.Option(help="File unit (see `info`).")]


def _kinect_command(device: str) -> Callable[..., None]:
    """The ``render DEVICE`` command of one Kinect model."""

    def kinect(
        motion: MotionArg,
        out: OutOpt = Path("out/render"),
        duration_s: DurationOpt = None,
        start: StartOpt = 0.0,
        end: EndOpt = None,
        sensor_pos: Annotated[
            str | None,
            typer.Option(
                help="Sensor position 'X,Y,Z' in metres (Z up). Default: set up in front of "
                "the performer, the whole take in range where the sensor allows."
            ),
        ] = None,
        sensor_yaw: Annotated[
            float | None,
            typer.Option(help="Heading of the optical axis in degrees (0 = +X, 90 = +Y)."),
        ] = None,
        sensor_pitch: Annotated[
            float | None, typer.Option(help="Tilt of the optical axis in degrees (negative: down).")
        ] = None,
        sensor_look_at: Annotated[
            str | None,
            typer.Option(
                help="Point 'X,Y,Z' the sensor aims at (default with --sensor-pos: the performer)."
            ),
        ] = None,
        sensor_height: Annotated[
            float | None, typer.Option(help="Height in metres of the automatic set-up (0.9).")
        ] = None,
        kinect_skeleton: KinectSkeletonOpt = "tracker",
        unit: UnitOpt = None,
        seed: SeedOpt = 0,
        json_out: JsonOpt = None,
    ) -> None:
        from avatarsim.render_cams.kinect.device import Kinect
        from avatarsim.render_cams.kinect.placement import look_at, performer_target
        from avatarsim.render_cams.kinect.sequence import write_kinect_recording

        pos_xyz, pose, height = _kinect_placement(
            sensor_pos, sensor_yaw, sensor_pitch, sensor_look_at, sensor_height
        )

        def record(humanoid: Humanoid, folder: Path) -> dict:
            aim = pose
            if pos_xyz is not None and aim is None:  # aimed at the performer
                aim = look_at(pos_xyz, performer_target(humanoid.motion))
            kinect = Kinect(
                device, sensor_pose=aim, sensor_height_m=height, skeleton=kinect_skeleton
            )
            return write_kinect_recording(
                kinect.sample(humanoid.motion, seed, humanoid.body), folder
            )

        _render(device, record, motion, out, duration_s, start, end, unit, seed, json_out)

    kinect.__doc__ = (
        f"What the {device} sensor records of MOTION.\n\n16-bit depth PNG in mm, body-index "
        "PNG, body-part label PNG, skeleton JSON per frame (tracked on the depth; "
        "--kinect-skeleton oracle-noise: the true joints plus noise, not a sensor) and a "
        "preview video."
    )
    return kinect


def register(app: typer.Typer) -> None:
    from avatarsim.scripts.cli_legacy import legacy_group

    group = typer.Typer(
        cls=legacy_group(_old_render),
        no_args_is_help=True,
        help="What a device would record of a motion: images, depth, keypoints, a video.",
    )
    app.add_typer(group, name="render")

    @group.command()
    @user_errors
    def fisheye(
        motion: MotionArg,
        out: OutOpt = Path("out/render"),
        duration_s: DurationOpt = None,
        start: StartOpt = 0.0,
        end: EndOpt = None,
        fov: Annotated[
            str | None, typer.Option(help="Field of view 'H,V' in degrees (150,120).")
        ] = None,
        size: Annotated[
            str | None,
            typer.Option(
                help=f"Image size 'W,H' in pixels (640,480; {SIZE_RANGE[0]}-{SIZE_RANGE[1]} each)."
            ),
        ] = None,
        ring_offset: Annotated[
            str | None,
            typer.Option(
                help="Ring camera 'X,Y,Z' in metres in the controller frame (+X pointing, "
                "+Y left, +Z up; default 0.02,0,0.06)."
            ),
        ] = None,
        grip_offset: Annotated[
            str | None, typer.Option(help="Grip camera 'X,Y,Z' in metres (default -0.02,0,-0.06).")
        ] = None,
        ring_pitch: Annotated[
            float | None,
            typer.Option(help="Ring camera pitch in degrees above looking back (20)."),
        ] = None,
        grip_pitch: Annotated[
            float | None, typer.Option(help="Grip camera pitch in degrees (-45: looking down).")
        ] = None,
        unit: UnitOpt = None,
        seed: SeedOpt = 0,
        json_out: JsonOpt = None,
    ) -> None:
        """The four controller cameras on the hands of MOTION.

        PNG frames, 16-bit range in mm, keypoints JSON with the camera model per frame, MP4."""
        from avatarsim.render_cams.fisheye.sequence import write_fisheye_recording

        rig = _fisheye_rig(fov, size, ring_offset, grip_offset, ring_pitch, grip_pitch)

        def record(humanoid: Humanoid, folder: Path) -> dict:
            recording = rig.sample(humanoid.motion, seed, humanoid.body)
            return write_fisheye_recording(recording, folder)

        _render("fisheye", record, motion, out, duration_s, start, end, unit, seed, json_out)

    for device in KINECT_DEVICES:
        group.command(name=device)(user_errors(_kinect_command(device)))
