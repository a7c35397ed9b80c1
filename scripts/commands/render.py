"""``avatarsim render MOTION --device ...``: what a device would record, written to a folder.

fisheye: the four controller cameras (PNG frames, 16-bit range in mm, keypoints JSON with the
camera model per frame, MP4). kinect-v2 / azure-kinect: 16-bit depth PNG in mm, body-index
PNG, skeleton JSON per frame, preview video.

The frame range is ``--start`` to ``--end`` seconds of the clip (``--end end``: to its end), or
``--duration-s`` seconds from ``--start`` (default 2 s, cut at the clip's end). Options of one
kind of device given with another exit 2.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Annotated, Any

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
DEFAULT_DURATION_S = 2.0
MAX_DURATION_S = 600.0  # seconds of motion rendered (about 30 frames per second of it)
SIZE_RANGE = (16, 4096)  # fisheye image side in pixels
FISHEYE_OPTIONS = (
    "--fov",
    "--size",
    "--ring-offset",
    "--grip-offset",
    "--ring-pitch",
    "--grip-pitch",
)
KINECT_OPTIONS = (
    "--sensor-pos",
    "--sensor-yaw",
    "--sensor-pitch",
    "--sensor-look-at",
    "--sensor-height",
)


def _numbers(text: str | None, option: str, n: int, kind=float) -> tuple | None:
    """``"A,B[,C]"`` -> ``n`` finite numbers of ``kind``; a clear error for anything else."""
    from avatar_models.errors import AvatarsimError

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
    from avatar_models.errors import AvatarsimError

    if not math.isfinite(degrees):
        raise AvatarsimError(f"angles must be finite numbers of degrees, got {degrees}")
    return math.radians(degrees)


def _pair(text: str | None, option: str, default: tuple, kind=float) -> tuple:
    """``"A,B"`` -> ``(A, B)`` of ``kind``; a clear error for anything else."""
    return _numbers(text, option, 2, kind) or default


def _check_device_options(device: str, given: dict[str, object]) -> None:
    """Exit 2 for an option that the chosen device does not have (it would be ignored)."""
    from avatar_models.errors import AvatarsimError

    foreign = KINECT_OPTIONS if device == "fisheye" else FISHEYE_OPTIONS
    wrong = [name for name in foreign if given.get(name) is not None]
    if wrong:
        kind = "a Kinect device" if device == "fisheye" else "--device fisheye"
        raise AvatarsimError(f"{', '.join(wrong)} only apply to {kind}, not to --device {device}")
    if given.get("--sensor-pos") is None:
        needs = [
            n
            for n in ("--sensor-yaw", "--sensor-pitch", "--sensor-look-at")
            if given.get(n) is not None
        ]
        if needs:
            raise AvatarsimError(f"{', '.join(needs)} need --sensor-pos (where the sensor stands)")
    elif given.get("--sensor-height") is not None:
        raise AvatarsimError("give --sensor-pos (its z is the height) or --sensor-height, not both")
    if given.get("--sensor-look-at") is not None and (
        given.get("--sensor-yaw") is not None or given.get("--sensor-pitch") is not None
    ):
        raise AvatarsimError("give --sensor-look-at or --sensor-yaw/--sensor-pitch, not both")


def _parse_range(start_s: float, end: str | None) -> float | str | None:
    """``--end`` as seconds after a valid ``--start``, ``"end"``, or None (checked before any
    motion is loaded)."""
    from avatar_models.errors import AvatarsimError

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
    from avatar_models.errors import AvatarsimError

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


def _device_option(kind: type, help: str) -> Any:
    """An optional device option of type ``kind`` (None when not given)."""
    return Annotated[kind | None, typer.Option(help=help)]


def _fisheye_rig(options: dict[str, Any]):
    """The ``FisheyeRig`` the fisheye options describe (checked before any motion loads)."""
    from avatar_models.errors import AvatarsimError
    from render_cams.fisheye.device import FisheyeRig
    from render_cams.fisheye.model import FisheyeModel
    from render_cams.fisheye.rig import Mount

    fov_deg = _pair(options["--fov"], "--fov", (150, 120))
    size_px = _pair(options["--size"], "--size", (640, 480), int)
    if not all(0 < v < 180 for v in fov_deg):
        raise AvatarsimError(
            f"--fov: a FOV must be two angles in (0, 180) degrees, got {options['--fov']!r}"
        )
    lo, hi = SIZE_RANGE
    if not all(lo <= v <= hi for v in size_px):
        raise AvatarsimError(
            f"--size must be two sides of {lo}-{hi} pixels, got {options['--size']!r}"
        )
    default = Mount()
    ring_pitch, grip_pitch = options["--ring-pitch"], options["--grip-pitch"]
    mount = Mount(
        ring_offset_m=_numbers(options["--ring-offset"], "--ring-offset", 3)
        or default.ring_offset_m,
        grip_offset_m=_numbers(options["--grip-offset"], "--grip-offset", 3)
        or default.grip_offset_m,
        ring_pitch_rad=default.ring_pitch_rad if ring_pitch is None else _rad(ring_pitch),
        grip_pitch_rad=default.grip_pitch_rad if grip_pitch is None else _rad(grip_pitch),
    )
    return FisheyeRig(model=FisheyeModel.from_fov(*fov_deg, *size_px), mount=mount)


def _kinect_placement(options: dict[str, Any]) -> tuple[tuple | None, Any, float]:
    """``(position, camera_to_world, height)`` from the Kinect options: the pose is None for
    the automatic set-up (at ``height``) and for a position aimed at the performer (then
    ``position`` is set; the pose follows from the motion)."""
    from render_cams.kinect.placement import (
        DEFAULT_HEIGHT_M,
        KinectPlacementError,
        look_at,
        yaw_pitch_pose,
    )

    pos_xyz = _numbers(options["--sensor-pos"], "--sensor-pos", 3)
    look_xyz = _numbers(options["--sensor-look-at"], "--sensor-look-at", 3)
    yaw, pitch, height = (
        options["--sensor-yaw"],
        options["--sensor-pitch"],
        options["--sensor-height"],
    )
    height = DEFAULT_HEIGHT_M if height is None else height
    if pos_xyz is not None and pos_xyz[2] < 0:
        raise KinectPlacementError(f"--sensor-pos z = {pos_xyz[2]} m is below the floor")
    if not (math.isfinite(height) and 0.0 <= height <= 3.0):
        raise KinectPlacementError(f"--sensor-height must be in [0, 3] m, got {height}")
    pose = None
    if yaw is not None or pitch is not None:
        pose = yaw_pitch_pose(pos_xyz, _rad(yaw or 0.0), _rad(pitch or 0.0))
    elif look_xyz is not None:
        pose = look_at(pos_xyz, look_xyz)
    return pos_xyz, pose, height


def _record(device: str, options: dict[str, Any], humanoid, seed: int, out: Path) -> dict:
    """Record the humanoid's motion with ``device`` (its options were checked before the
    motion was loaded) into ``out``; return the written recording's summary."""
    if device == "fisheye":
        from render_cams.fisheye.sequence import write_fisheye_recording

        recording = _fisheye_rig(options).sample(humanoid.motion, seed, humanoid.body)
        return write_fisheye_recording(recording, out)
    from render_cams.kinect.device import Kinect
    from render_cams.kinect.placement import look_at, performer_target
    from render_cams.kinect.sequence import write_kinect_recording

    pos_xyz, pose, height = _kinect_placement(options)
    if pos_xyz is not None and pose is None:  # aimed at the performer
        pose = look_at(pos_xyz, performer_target(humanoid.motion))
    kinect = Kinect(device, sensor_pose=pose, sensor_height_m=height)
    return write_kinect_recording(kinect.sample(humanoid.motion, seed, humanoid.body), out)


def register(app: typer.Typer) -> None:
    @app.command()
    @user_errors
    def render(
        motion: Annotated[str, typer.Argument(help="Motion file, or builtin:ACTIVITY.")],
        device: Annotated[str, typer.Option(help=f"One of: {', '.join(DEVICES)}.")] = "fisheye",
        out: Annotated[Path, typer.Option(help="Output folder.")] = Path("out/render"),
        duration_s: Annotated[
            float | None,
            typer.Option(help="Seconds to record from --start (default 2, cut at the clip's end)."),
        ] = None,
        start: Annotated[float, typer.Option(help="First second of the clip to record.")] = 0.0,
        end: Annotated[
            str | None,
            typer.Option(help="Last second of the clip to record, or 'end' (the whole clip)."),
        ] = None,
        fov: _device_option(str, "fisheye: field of view 'H,V' in degrees (150,120).") = None,
        size: _device_option(
            str,
            f"fisheye: image size 'W,H' in pixels (640,480; {SIZE_RANGE[0]}-{SIZE_RANGE[1]} each).",
        ) = None,
        ring_offset: _device_option(
            str,
            "fisheye: ring camera 'X,Y,Z' in metres in the controller frame "
            "(+X pointing, +Y left, +Z up; default 0.02,0,0.06).",
        ) = None,
        grip_offset: _device_option(
            str, "fisheye: grip camera 'X,Y,Z' in metres (default -0.02,0,-0.06)."
        ) = None,
        ring_pitch: _device_option(
            float, "fisheye: ring camera pitch in degrees above looking back (32.5)."
        ) = None,
        grip_pitch: _device_option(
            float, "fisheye: grip camera pitch in degrees (-32.5: looking down)."
        ) = None,
        sensor_pos: _device_option(
            str,
            "Kinect: sensor position 'X,Y,Z' in metres (Z up). Default: set up in front of the "
            "performer, the whole take in range where the sensor allows.",
        ) = None,
        sensor_yaw: _device_option(
            float, "Kinect: heading of the optical axis in degrees (0 = +X, 90 = +Y)."
        ) = None,
        sensor_pitch: _device_option(
            float, "Kinect: tilt of the optical axis in degrees (negative: down)."
        ) = None,
        sensor_look_at: _device_option(
            str,
            "Kinect: point 'X,Y,Z' the sensor aims at (default with --sensor-pos: the performer).",
        ) = None,
        sensor_height: _device_option(
            float, "Kinect: height in metres of the automatic set-up (0.9)."
        ) = None,
        unit: Annotated[str | None, typer.Option(help="File unit (see `info`).")] = None,
        seed: SeedOpt = 0,
        json_out: JsonOpt = None,
    ) -> None:
        """Images, depth, keypoints and a video that a device would record of MOTION."""
        from avatar_models.errors import AvatarsimError

        if device not in DEVICES:
            raise AvatarsimError(f"unknown device {device!r}; devices: {', '.join(DEVICES)}")
        options = {
            "--fov": fov,
            "--size": size,
            "--ring-offset": ring_offset,
            "--grip-offset": grip_offset,
            "--ring-pitch": ring_pitch,
            "--grip-pitch": grip_pitch,
            "--sensor-pos": sensor_pos,
            "--sensor-yaw": sensor_yaw,
            "--sensor-pitch": sensor_pitch,
            "--sensor-look-at": sensor_look_at,
            "--sensor-height": sensor_height,
        }
        _check_device_options(device, options)
        if duration_s is not None and end is not None:
            raise AvatarsimError("give --end or --duration-s, not both")
        if duration_s is not None and not 0 < duration_s <= MAX_DURATION_S:
            raise AvatarsimError(
                f"--duration-s must be above 0 and at most {MAX_DURATION_S:g}, got {duration_s}"
            )
        end_at = _parse_range(start, end)
        if isinstance(end_at, float) and end_at - start > MAX_DURATION_S:
            raise AvatarsimError(f"--start to --end spans more than {MAX_DURATION_S:g} s")
        # Every device option is checked before the motion is loaded and retargeted.
        if device == "fisheye":
            _fisheye_rig(options)
        else:
            _kinect_placement(options)

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
        from sim.humanoid import humanoid_for

        humanoid = humanoid_for(m)
        t0 = time.perf_counter()
        summary = _record(device, options, humanoid, seed, out)
        elapsed = time.perf_counter() - t0
        summary = dict(summary)
        summary.setdefault("fps_rendered", summary.get("frames", 0) / max(elapsed, 1e-9))
        summary["start_s"], summary["end_s"] = round(start_s, 6), round(end_s, 6)
        console.print(
            escape(
                f"{device}: {summary.get('frames')} frames ({start_s:.2f}-{end_s:.2f} s) in "
                f"{elapsed:.1f} s ({summary['fps_rendered']:.1f} frames/s) -> {out}/"
            )
        )
        emit_json(json_out, {"device": device, "out_dir": str(out), **summary})
