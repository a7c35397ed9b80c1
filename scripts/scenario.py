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

Read by :mod:`avatar_models.config`: unknown keys, wrong types and impossible values raise
:class:`ScenarioError` (a :class:`~avatar_models.config.ConfigError`) naming the key. The
frames a scenario asks for are bounded by memory (:func:`avatar_models.memory.require_memory`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from avatarsim.avatar_models.config import ConfigError, from_data, read_toml, setting
from avatarsim.avatar_models.errors import AvatarsimError
from avatarsim.avatar_models.memory import FRAME_BYTES, require_memory
from avatarsim.avatar_models.mocap_dir import MocapUnset, is_mocap_source, resolve_mocap_source
from avatarsim.avatar_models.motion import FPS_RANGE
from avatarsim.render_cams.kinect.sensors import SENSORS

KINECT_SENSORS = tuple(SENSORS)
# sim.corrupt's defects a scenario's motion can be given (``motion.corrupt``), each one that a
# physics check must flag (scripts/corruption.py applies them).
CORRUPTIONS = ("sink_feet", "float_body", "bend_knee", "inject_sliding", "add_jitter")

# Bounds of a scenario's numbers (and the CLI's): beyond them a run is a typo that would
# compute for hours or measure nothing.
MIN_FRAMES = 3  # velocities need 2 frames, accelerations (residual forces, jitter) 3
MAX_MOTION_S = 600.0  # seconds of motion a scenario runs on
MAX_CONTROL_S = 600.0  # seconds followed under physics (the search runs slower than real time)
HUMAN_HEIGHT_M = (1.0, 2.5)


class ScenarioError(ConfigError):
    """A scenario file, or a suite of them, is missing, malformed or asks for something
    impossible."""


@dataclass(frozen=True)
class MotionSpec:
    source: str = "builtin"
    activity: str = "walk"
    duration_s: float = setting(4.0, gt=0.0, le=MAX_MOTION_S)
    fps: float = setting(90.0, ge=FPS_RANGE[0], le=FPS_RANGE[1])
    height_m: float | None = setting(None, ge=HUMAN_HEIGHT_M[0], le=HUMAN_HEIGHT_M[1])
    style: str | None = None
    unit: str | None = None
    corrupt: str | None = None  # one of CORRUPTIONS: the ground truth made physically wrong
    skip_if_absent: bool = False  # a missing motion file skips the scenario (real mocap)


@dataclass(frozen=True)
class BodySpec:
    mass_kg: float | None = setting(None, ge=10.0, le=300.0)  # None: the subject's, else 75 kg
    height_m: float | None = setting(None, ge=HUMAN_HEIGHT_M[0], le=HUMAN_HEIGHT_M[1])


@dataclass(frozen=True)
class ReportSpec:
    picture_frames: int = setting(6, ge=1, le=50)
    strip_span_s: float = setting(1.2, gt=0.0, le=60.0)  # about one stride: the frames differ
    gif: bool = True
    gif_fps: float = setting(15.0, ge=1.0, le=60.0)  # frame rates a GIF viewer plays


@dataclass(frozen=True)
class DevicesSpec:
    """Simulated VR tracking (``render_cams.vr``); ``noise`` is ``"none"`` or ``"realistic"``
    (Lighthouse-grade jitter, latency, slow drift). For sweeps, ``latency_s``, ``jitter_m``
    (position, per axis) and ``dropouts_per_s`` (0.5 s bursts of tracking loss) add one
    more model each, after the preset. ``kinect`` (``"kinect-v2"`` or ``"azure-kinect"``)
    also records the Kinect skeleton stream (30 Hz) that MoveBox runs on: ``kinect_skeleton``
    ``"tracker"`` (default) tracks it on the rendered depth as the SDK does, ``"oracle-noise"``
    takes the true joints plus noise (not a sensor: it never loses or swaps a joint; labelled
    so in the results). ``fisheye`` records
    the controller cameras' 2D keypoints too (ControllerPose's input)."""

    vr: bool = True
    kinect: str | None = None
    kinect_skeleton: Literal["tracker", "oracle-noise"] = "tracker"
    fisheye: bool = False
    trackers: bool = False
    noise: Literal["none", "realistic"] = "realistic"
    # sweep bounds: beyond them no tracking is left to synthesise from
    latency_s: float = setting(0.0, ge=0.0, le=1.0)
    jitter_m: float = setting(0.0, ge=0.0, le=0.5)
    dropouts_per_s: float = setting(0.0, ge=0.0, le=10.0)


@dataclass(frozen=True)
class SynthesisSpec:
    """Full-body synthesis from the VR stream. The CoolMoves database holds built-in takes of
    the scenario's activity by ``database_subjects`` other (seeded) subjects."""

    methods: tuple[str, ...] = ("coolmoves", "ik")
    database_subjects: int = setting(4, ge=1, le=50)
    database_duration_s: float = setting(8.0, gt=0.0, le=MAX_MOTION_S)
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

    seconds: float = setting(3.0, gt=0.0, le=MAX_CONTROL_S)
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
    seed: int = setting(0, ge=0)
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
    path: str | None = setting(None, from_file=False)  # the file, set by load_scenario


def _threshold(name: str, raw: Any) -> Threshold:
    where = f"thresholds.{name}"
    if isinstance(raw, Mapping) and raw and set(raw) <= {"min", "max"}:
        t = from_data(Threshold, raw, where)
        if t.min is not None and t.max is not None and t.min > t.max:
            raise ScenarioError(
                f"{where}: min {t.min:g} is above max {t.max:g}; nothing could pass"
            )
        return t
    if isinstance(raw, Mapping) or isinstance(raw, bool) or not isinstance(raw, int | float):
        raise ScenarioError(f"{where} must be a number (max) or a table {{min=, max=}}")
    return from_data(Threshold, {"max": raw}, where)


def parse_scenario(data: Any, path: str | None = None) -> Scenario:
    """Validate a parsed TOML table into a :class:`Scenario`."""
    try:
        return _parse(data, path)
    except ScenarioError:
        raise
    except ConfigError as exc:
        raise ScenarioError(str(exc)) from None


def _parse(data: Any, path: str | None) -> Scenario:
    if not isinstance(data, Mapping):
        raise ScenarioError("a scenario must be a table")
    table = dict(data)
    thresholds = table.pop("thresholds", {})
    if not isinstance(thresholds, Mapping):
        raise ScenarioError("[thresholds] must be a table")
    scenario = dataclasses.replace(
        from_data(Scenario, table),
        thresholds={k: _threshold(k, v) for k, v in thresholds.items()},
        path=path,
    )
    _check(scenario)
    return scenario


def _check(scenario: Scenario) -> None:
    """The rules across fields, and the frames a run holds against memory."""
    motion, devices, synthesis = scenario.motion, scenario.devices, scenario.synthesis
    if devices is not None and devices.kinect is not None and devices.kinect not in SENSORS:
        raise ScenarioError(
            f"devices.kinect must be one of {KINECT_SENSORS}, got {devices.kinect!r}"
        )
    if synthesis is not None and devices is None:
        raise ScenarioError("[synthesis] needs a [devices] table (the VR stream it runs on)")
    if motion.corrupt is not None and motion.corrupt not in CORRUPTIONS:
        raise ScenarioError(f"motion.corrupt must be one of {CORRUPTIONS}, got {motion.corrupt!r}")
    if motion.source == "builtin" and motion.unit is not None:
        raise ScenarioError("motion.unit applies to motion files; built-in motion is in metres")
    if motion.duration_s * motion.fps < MIN_FRAMES - 1:
        raise ScenarioError(
            f"motion.duration_s x motion.fps gives fewer than {MIN_FRAMES} frames: too short"
        )
    if any(v < 0 for v in scenario.regression.values()):
        raise ScenarioError("[regression] tolerances must be finite numbers, 0 or more")
    database_s = synthesis.database_subjects * synthesis.database_duration_s if synthesis else 0
    control_s = scenario.control.seconds if scenario.control else 0.0
    frames = (motion.duration_s + database_s + control_s) * motion.fps
    require_memory(
        frames * FRAME_BYTES,
        f"motion.duration_s x motion.fps ({frames:.0f} frames with the database and control)",
    )


def load_scenario(path: str | Path) -> Scenario:
    path = Path(path)
    if not path.is_file():
        raise ScenarioError(f"scenario file {path} does not exist")
    try:
        data = read_toml(path)
    except ConfigError as exc:
        raise ScenarioError(str(exc)) from None
    scenario = parse_scenario(data, str(path))
    source = scenario.motion.source
    if is_mocap_source(source):
        try:
            resolved = resolve_mocap_source(source)
        except MocapUnset as exc:
            if scenario.motion.skip_if_absent:
                return scenario  # the suite skips it, naming the unset folder
            raise ScenarioError(f"{path}: motion.source {exc}") from None
        except AvatarsimError as exc:
            raise ScenarioError(f"{path}: motion.source {exc}") from None
    elif source != "builtin" and not Path(source).is_absolute():
        # Motion files are relative to the scenario file, so scenarios can travel with data.
        resolved = (path.parent / source).resolve()
    else:
        return scenario
    return dataclasses.replace(
        scenario, motion=dataclasses.replace(scenario.motion, source=str(resolved))
    )


DEFAULT_SCENARIO = Path(__file__).parent / "scenarios" / "default.toml"
