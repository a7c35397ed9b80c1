"""Scenario files (TOML): schema, validation with actionable errors, and thresholds.

A scenario names a motion source, the body, the stages to run and pass/fail thresholds::

    name = "default"
    seed = 0
    [motion]
    source = "builtin"        # or a path to a .bvh / .amc / .npz file
    activity = "walk"         # builtin only (also: height_m, style; sampled from seed if absent)
    duration_s = 4.0
    fps = 90.0
    [body]
    mass_kg = 75.0            # optional
    [report]
    picture_frames = 6
    [thresholds]              # metric = max allowed, or {min = x} / {max = x}
    replay_error_mm_max = 1.0
    [physics]                 # sim.thresholds.CheckConfig overrides (definitions, thresholds)
    skate_cm_s_median = 40.0
    [control]                 # physics control of the ground truth (optional)
    seconds = 3.0
    search = true             # false: the plain controller (fast, lasts a few steps)
    expect_fail = ["penetration_cm_p95"]  # checks that must fail (a suite proving a detector)
    [regression]              # metric = tolerance against --baseline (defaults by metric kind)
    coolmoves_err_cm_full = 0.5

Unknown keys, wrong types and impossible values raise :class:`ScenarioError` naming the key.
"""

from __future__ import annotations

import dataclasses
import tomllib
import types
import typing
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from avatar_models.errors import AvatarsimError
from avatar_models.motion import FPS_RANGE
from render_cams.kinect.sensors import SENSORS

VR_NOISE = ("none", "realistic")
KINECT_SENSORS = tuple(SENSORS)
# sim.corrupt's defects a scenario's motion can be given (``motion.corrupt``), each one that a
# physics check must flag (scripts/corruption.py applies them).
CORRUPTIONS = ("sink_feet", "float_body", "bend_knee", "inject_sliding", "add_jitter")

# Bounds of a scenario's numbers (and the CLI's): beyond them a run is a typo that would
# compute for hours or measure nothing.
MIN_FRAMES = 3  # velocities need 2 frames, accelerations (residual forces, jitter) 3
MAX_MOTION_S = 600.0  # seconds of motion a scenario runs on
MAX_CONTROL_S = 600.0  # seconds followed under physics (the search runs slower than real time)
MAX_PICTURE_FRAMES = 50  # frames in the report's strip
GIF_FPS_RANGE = (1.0, 60.0)  # frame rates a GIF viewer plays
MAX_STRIP_SPAN_S = 60.0
MAX_DATABASE_SUBJECTS = 50
MASS_RANGE_KG = (10.0, 300.0)
# devices.* sweep bounds: beyond them no tracking is left to synthesise from.
DEVICE_SWEEP_MAX = {"latency_s": 1.0, "jitter_m": 0.5, "dropouts_per_s": 10.0}


class ScenarioError(AvatarsimError):
    """A scenario file is missing, malformed or asks for something impossible."""


@dataclass(frozen=True)
class MotionSpec:
    source: str = "builtin"
    activity: str = "walk"
    duration_s: float = 4.0
    fps: float = 90.0
    height_m: float | None = None
    style: str | None = None
    unit: str | None = None
    corrupt: str | None = None  # one of CORRUPTIONS: the ground truth made physically wrong
    skip_if_absent: bool = False  # a missing motion file skips the scenario (real mocap)


@dataclass(frozen=True)
class BodySpec:
    mass_kg: float | None = None  # None: the built-in subject's mass, else 75 kg
    height_m: float | None = None


@dataclass(frozen=True)
class ReportSpec:
    picture_frames: int = 6
    strip_span_s: float = 1.2  # the strip spans about one stride, so the frames differ
    gif: bool = True
    gif_fps: float = 15.0


@dataclass(frozen=True)
class DevicesSpec:
    """Simulated VR tracking (``render_cams.vr``); ``noise`` is ``"none"`` or ``"realistic"``
    (Lighthouse-grade jitter, latency, slow drift). For sweeps, ``latency_s``, ``jitter_m``
    (position, per axis) and ``dropouts_per_s`` (0.5 s bursts of tracking loss) add one
    more model each, after the preset. ``kinect`` (``"kinect-v2"`` or ``"azure-kinect"``)
    also records the Kinect skeleton stream (30 Hz) that MoveBox runs on. ``fisheye`` records
    the controller cameras' 2D keypoints too (ControllerPose's input)."""

    vr: bool = True
    kinect: str | None = None
    fisheye: bool = False
    trackers: bool = False
    noise: str = "realistic"
    latency_s: float = 0.0
    jitter_m: float = 0.0
    dropouts_per_s: float = 0.0


@dataclass(frozen=True)
class SynthesisSpec:
    """Full-body synthesis from the VR stream. The CoolMoves database holds built-in takes of
    the scenario's activity by ``database_subjects`` other (seeded) subjects."""

    methods: tuple[str, ...] = ("coolmoves", "ik")
    database_subjects: int = 4
    database_duration_s: float = 8.0
    foot_contact: bool = True  # CoolMoves' stance-foot clean-up (beyond the paper)


@dataclass(frozen=True)
class CamerasSpec:
    """Rendered device views for the report: controller fisheye cameras, a Kinect."""

    fisheye: bool = True
    kinect: str | None = "kinect-v2"


@dataclass(frozen=True)
class ControlSpec:
    """Physics control of the ground truth (the search of ``sim.control.search``, or the
    plain controller): ``seconds`` followed from the start, the clip looped when shorter."""

    seconds: float = 3.0
    search: bool = True


@dataclass(frozen=True)
class Threshold:
    """Pass when ``value <= max`` (and/or ``value >= min``)."""

    max: float | None = None
    min: float | None = None

    def passes(self, value: float) -> bool:
        if value != value:  # NaN never passes
            return False
        return (self.max is None or value <= self.max) and (self.min is None or value >= self.min)

    def describe(self) -> str:
        parts = ([f"<= {self.max:g}"] if self.max is not None else []) + (
            [f">= {self.min:g}"] if self.min is not None else []
        )
        return " and ".join(parts)


@dataclass(frozen=True)
class Scenario:
    name: str = "scenario"
    seed: int = 0
    motion: MotionSpec = field(default_factory=MotionSpec)
    body: BodySpec = field(default_factory=BodySpec)
    report: ReportSpec = field(default_factory=ReportSpec)
    devices: DevicesSpec | None = None
    synthesis: SynthesisSpec | None = None
    cameras: CamerasSpec | None = None
    control: ControlSpec | None = None
    thresholds: dict[str, Threshold] = field(default_factory=dict)
    physics: dict[str, float] = field(default_factory=dict)
    expect_fail: tuple[str, ...] = ()
    regression: dict[str, float] = field(default_factory=dict)
    path: str | None = None


def _check_type(value: Any, annotation: Any, where: str) -> Any:
    """Coerce ints to floats where a float is expected; reject anything else of a wrong type."""
    allowed = (
        typing.get_args(annotation) if isinstance(annotation, types.UnionType) else (annotation,)
    )
    if value is None and type(None) in allowed:
        return value
    if typing.get_origin(annotation) is tuple:
        item = typing.get_args(annotation)[0]
        if not isinstance(value, list):
            raise ScenarioError(f"{where} must be a list, got {value!r}")
        return tuple(_check_type(v, item, f"{where}[{i}]") for i, v in enumerate(value))
    for typ in allowed:
        if typ is float and isinstance(value, int | float) and not isinstance(value, bool):
            return float(value)
        if typ in (int, str, bool) and type(value) is typ:
            return value
    names = " or ".join(getattr(t, "__name__", str(t)) for t in allowed if t is not type(None))
    raise ScenarioError(f"{where} must be {names}, got {value!r}")


def _section(cls: type, table: Any, where: str) -> Any:
    if not isinstance(table, dict):
        raise ScenarioError(f"[{where}] must be a table")
    hints = typing.get_type_hints(cls)
    known = {f.name for f in dataclasses.fields(cls)}
    unknown = sorted(set(table) - known)
    if unknown:
        raise ScenarioError(f"unknown key(s) {unknown} in [{where}]; allowed: {sorted(known)}")
    return cls(**{k: _check_type(v, hints[k], f"{where}.{k}") for k, v in table.items()})


def _threshold(name: str, raw: Any) -> Threshold:
    if isinstance(raw, int | float) and not isinstance(raw, bool):
        if raw != raw or raw in (float("inf"), float("-inf")):
            raise ScenarioError(f"thresholds.{name} must be a finite number, got {raw!r}")
        return Threshold(max=float(raw))
    if isinstance(raw, dict) and raw and set(raw) <= {"min", "max"}:
        t = _section(Threshold, raw, f"thresholds.{name}")
        bounds = [b for b in (t.min, t.max) if b is not None]
        if any(b != b or abs(b) == float("inf") for b in bounds):
            raise ScenarioError(f"thresholds.{name} bounds must be finite numbers")
        if t.min is not None and t.max is not None and t.min > t.max:
            raise ScenarioError(
                f"thresholds.{name}: min {t.min:g} is above max {t.max:g}; nothing could pass"
            )
        return t
    raise ScenarioError(f"thresholds.{name} must be a number (max) or a table {{min=, max=}}")


def parse_scenario(data: dict[str, Any], path: str | None = None) -> Scenario:
    """Validate a parsed TOML table into a :class:`Scenario`."""
    top = {"name", "seed", "motion", "body", "report", "devices", "synthesis", "cameras"}
    top |= {"control", "thresholds", "physics", "expect_fail", "regression"}
    unknown = sorted(set(data) - top)
    if unknown:
        raise ScenarioError(f"unknown top-level key(s) {unknown}; allowed: {sorted(top)}")
    motion = _section(MotionSpec, data.get("motion", {}), "motion")
    body = _section(BodySpec, data.get("body", {}), "body")
    report = _section(ReportSpec, data.get("report", {}), "report")
    optional = {
        key: _section(cls, data[key], key) if key in data else None
        for key, cls in (
            ("devices", DevicesSpec),
            ("synthesis", SynthesisSpec),
            ("cameras", CamerasSpec),
            ("control", ControlSpec),
        )
    }
    if optional["control"] and not 0 < optional["control"].seconds <= MAX_CONTROL_S:
        raise ScenarioError(f"control.seconds must be above 0 and at most {MAX_CONTROL_S:g}")
    if optional["devices"] and optional["devices"].noise not in VR_NOISE:
        raise ScenarioError(f"devices.noise must be one of {VR_NOISE}")
    for key, most in DEVICE_SWEEP_MAX.items():
        value = getattr(optional["devices"], key, 0.0)
        if not 0 <= value <= most:
            raise ScenarioError(f"devices.{key} must be 0-{most:g}, got {value}")
    kinect = getattr(optional["devices"], "kinect", None)
    if kinect is not None and kinect not in KINECT_SENSORS:
        raise ScenarioError(f"devices.kinect must be one of {KINECT_SENSORS}, got {kinect!r}")
    if optional["synthesis"] and not optional["devices"]:
        raise ScenarioError("[synthesis] needs a [devices] table (the VR stream it runs on)")
    synthesis = optional["synthesis"]
    if synthesis and not 1 <= synthesis.database_subjects <= MAX_DATABASE_SUBJECTS:
        raise ScenarioError(
            f"synthesis.database_subjects must be 1-{MAX_DATABASE_SUBJECTS}, "
            f"got {synthesis.database_subjects}"
        )
    if synthesis and not 0 < synthesis.database_duration_s <= MAX_MOTION_S:
        raise ScenarioError(
            f"synthesis.database_duration_s must be above 0, at most {MAX_MOTION_S:g}"
        )
    if motion.corrupt is not None and motion.corrupt not in CORRUPTIONS:
        raise ScenarioError(f"motion.corrupt must be one of {CORRUPTIONS}, got {motion.corrupt!r}")
    if not 0 < motion.duration_s <= MAX_MOTION_S:
        raise ScenarioError(
            f"motion.duration_s must be above 0 and at most {MAX_MOTION_S:g}, "
            f"got {motion.duration_s}"
        )
    if motion.source == "builtin" and motion.unit is not None:
        raise ScenarioError("motion.unit applies to motion files; built-in motion is in metres")
    lo, hi = FPS_RANGE
    if not lo <= motion.fps <= hi:
        raise ScenarioError(f"motion.fps must be {lo:g}-{hi:g}, got {motion.fps}")
    if motion.duration_s * motion.fps < MIN_FRAMES - 1:
        raise ScenarioError(
            f"motion.duration_s x motion.fps gives fewer than {MIN_FRAMES} frames: too short"
        )
    if motion.height_m is not None and not 1.0 <= motion.height_m <= 2.5:
        raise ScenarioError(f"motion.height_m={motion.height_m} is not a human height in metres")
    if body.height_m is not None and not 1.0 <= body.height_m <= 2.5:
        raise ScenarioError(f"body.height_m={body.height_m} is not a human height in metres")
    lo, hi = MASS_RANGE_KG
    if body.mass_kg is not None and not lo <= body.mass_kg <= hi:
        raise ScenarioError(f"body.mass_kg must be {lo:g}-{hi:g}, got {body.mass_kg}")
    if not 0 < report.strip_span_s <= MAX_STRIP_SPAN_S:
        raise ScenarioError(
            f"report.strip_span_s must be above 0 and at most {MAX_STRIP_SPAN_S:g}, "
            f"got {report.strip_span_s}"
        )
    if not 1 <= report.picture_frames <= MAX_PICTURE_FRAMES:
        raise ScenarioError(
            f"report.picture_frames must be 1-{MAX_PICTURE_FRAMES}, got {report.picture_frames}"
        )
    lo, hi = GIF_FPS_RANGE
    if not lo <= report.gif_fps <= hi:
        raise ScenarioError(f"report.gif_fps must be {lo:g}-{hi:g}, got {report.gif_fps}")
    thresholds_raw = data.get("thresholds", {})
    if not isinstance(thresholds_raw, dict):
        raise ScenarioError("[thresholds] must be a table")
    thresholds = {k: _threshold(k, v) for k, v in thresholds_raw.items()}
    physics = data.get("physics", {})
    if not isinstance(physics, dict):
        raise ScenarioError("[physics] must be a table of check settings")
    expect_fail = _check_type(data.get("expect_fail", []), tuple[str, ...], "expect_fail")
    regression = data.get("regression", {})
    if not isinstance(regression, dict):
        raise ScenarioError("[regression] must be a table of metric = tolerance")
    regression = {k: _check_type(v, float, f"regression.{k}") for k, v in regression.items()}
    if any(not 0 <= v < float("inf") for v in regression.values()):
        raise ScenarioError("[regression] tolerances must be finite numbers, 0 or more")
    seed = _check_type(data.get("seed", 0), int, "seed")
    if seed < 0:
        raise ScenarioError(f"seed must be 0 or more, got {seed}")
    return Scenario(
        name=_check_type(data.get("name", "scenario"), str, "name"),
        seed=seed,
        motion=motion,
        body=body,
        report=report,
        **optional,
        thresholds=thresholds,
        physics=physics,
        expect_fail=expect_fail,
        regression=regression,
        path=path,
    )


def load_scenario(path: str | Path) -> Scenario:
    path = Path(path)
    if not path.is_file():
        raise ScenarioError(f"scenario file {path} does not exist")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ScenarioError(f"{path}: not valid TOML ({exc})") from exc
    scenario = parse_scenario(data, str(path))
    source = scenario.motion.source
    if source != "builtin" and not Path(source).is_absolute():
        # Motion files are relative to the scenario file, so scenarios can travel with data.
        resolved = (path.parent / source).resolve()
        scenario = dataclasses.replace(
            scenario, motion=dataclasses.replace(scenario.motion, source=str(resolved))
        )
    return scenario


DEFAULT_SCENARIO = Path(__file__).parent / "scenarios" / "default.toml"
