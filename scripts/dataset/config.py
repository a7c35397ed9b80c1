"""The dataset config: a TOML file, checked whole before anything is written.

A config crosses motion sources (``[[sources]]``: built-in activities x sampled subjects, or
a mocap folder) with device sets (``[[devices]]``) and assigns every subject, clip or
performer to one split (``[splits]``). Every key is known: an unknown one is a
:class:`ConfigError` (exit 2), as are an empty source, split fractions not summing to 1 and
bad values. :func:`config_hash` is the sha256 of the normalised config (seed included), the
dataset's identity for resume and provenance.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from dataclasses import MISSING, asdict, dataclass, field, fields, replace
from pathlib import Path
from typing import Any, Literal

from avatarsim.avatar_models.config import ConfigError, from_data, read_toml, setting
from avatarsim.avatar_models.generator import ACTIVITIES
from avatarsim.avatar_models.mocap_dir import is_mocap_source
from avatarsim.avatar_models.motion import FPS_RANGE
from avatarsim.render_cams.fisheye.device import SCALE_RANGE
from avatarsim.render_cams.kinect.placement import DEFAULT_HEIGHT_M
from avatarsim.scripts.dataset.budget import check_budget

SPLITS = ("train", "val", "test")
SPLIT_TOLERANCE = 1e-6
SourceKind = Literal["builtin", "mocap"]
VrNoise = Literal["none", "realistic"]
KinectSensor = Literal["none", "kinect-v2", "azure-kinect"]
KinectSkeleton = Literal["tracker", "oracle-noise"]
ImageFormat = Literal["none", "jpeg", "png"]
MocapSplitBy = Literal["clip", "performer"]


@dataclass(frozen=True)
class WindowConfig:
    """One sample is one window of a clip: ``seconds`` long, ground truth at ``fps`` (Hz, in
    :data:`avatar_models.motion.FPS_RANGE`). Their product is bounded by memory
    (:mod:`scripts.dataset.budget`)."""

    seconds: float = setting(4.0, gt=0.0)
    fps: float = setting(30.0, ge=FPS_RANGE[0], le=FPS_RANGE[1])


@dataclass(frozen=True)
class SourceConfig:
    """A motion source.

    Attributes:
        kind: ``"builtin"`` (the procedural generator) or ``"mocap"`` (a folder, indexed by
            :class:`avatar_models.library.MotionLibrary`).
        activities: activities to use (builtin: default all; mocap: a filter, default all).
        subjects: builtin: number of sampled subjects.
        windows: windows per subject x activity (builtin) or per clip (mocap).
        path: mocap: the folder, or one clip (relative to the config file's folder when
            read by :func:`load_config`; ``mocap:RELATIVE/PATH``: inside the machine's mocap
            folder, :mod:`avatar_models.mocap_dir`).
        split_by: mocap: ``"clip"`` or ``"performer"`` (the library's subject label).
    """

    kind: SourceKind
    activities: tuple[str, ...] = ()
    subjects: int = setting(0, ge=0)
    windows: int = setting(1, ge=1)
    path: str = ""
    split_by: MocapSplitBy = "clip"


@dataclass(frozen=True)
class DeviceSetConfig:
    """What one sample records of its window.

    Attributes:
        name: the device set's name (part of every sample key; default ``set{k}``).
        vr: headset + controllers at 90 Hz; ``trackers`` adds the Vive trackers.
        vr_noise: ``"none"`` or ``"realistic"`` (render_cams.vr.noise.REALISTIC_NOISE).
        fisheye: projected 2D keypoints of the controller cameras.
        fisheye_images: ``"none"``, ``"jpeg"`` or ``"png"``: the cameras' rendered images
            (needs ``fisheye``).
        kinect: ``"none"``, ``"kinect-v2"`` or ``"azure-kinect"``: the skeleton with
            tracking states.
        kinect_skeleton: ``"tracker"`` (tracked on the rendered depth, as the SDK does) or
            ``"oracle-noise"`` (the true joints plus noise: not a sensor, labelled so in
            every sample's JSON).
        kinect_depth: the Kinect's 16-bit depth images in millimetres, PNG (needs a
            ``kinect``).
        kinect_parts: the body-part label image aligned with each depth image, 8-bit PNG
            (part ``k + 1``: body17 joint ``k``, 0: no body; needs ``kinect_depth``).
        kinect_yaw_deg: the sensor turned about the performer by this many degrees from its
            set-up in front of them (0: front, 90: their left side, 180: behind).
        kinect_height_m: the sensor's height above the floor.
        image_stride: images and depth of every ``image_stride``-th camera frame (rendering
            is most of a sample's time; 3 gives 10 Hz at the cameras' 30 Hz).
        image_scale: fisheye image size factor (1: 640 x 480).
        physics: per-frame physics labels (contact, penetration, skate).
    """

    name: str
    vr: bool = True
    trackers: bool = False
    vr_noise: VrNoise = "none"
    fisheye: bool = True
    fisheye_images: ImageFormat = "none"
    kinect: KinectSensor = "none"
    kinect_skeleton: KinectSkeleton = "tracker"
    kinect_depth: bool = False
    kinect_parts: bool = False
    kinect_yaw_deg: float = setting(0.0, ge=-180.0, le=180.0)
    kinect_height_m: float = setting(DEFAULT_HEIGHT_M, ge=0.2, le=2.5)
    image_stride: int = setting(3, ge=1)
    image_scale: float = setting(0.5, ge=SCALE_RANGE[0], le=SCALE_RANGE[1])
    physics: bool = True


@dataclass(frozen=True)
class DatasetConfig:
    """A whole dataset config (module docstring)."""

    name: str
    seed: int = setting(0, ge=0)
    samples_per_shard: int = setting(64, ge=1)
    window: WindowConfig = field(default_factory=WindowConfig)
    splits: dict[str, float] = setting(
        default_factory=lambda: dict(zip(SPLITS, (0.8, 0.1, 0.1), strict=True)),
        max_items=len(SPLITS),
    )
    sources: tuple[SourceConfig, ...] = ()
    devices: tuple[DeviceSetConfig, ...] = ()

    def with_seed(self, seed: int | None) -> DatasetConfig:
        return self if seed is None else replace(self, seed=int(seed))

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready, as :func:`from_dict` reads it back."""
        return json.loads(json.dumps(asdict(self)))


def config_hash(config: DatasetConfig) -> str:
    """sha256 (hex) of the normalised config, keys sorted, each source's and device set's
    keys at their defaults left out: a key added later whose default keeps the old output
    (a new channel, off unless asked for) leaves the hash, and so resuming and verifying
    datasets made before it, unchanged. ``kinect_skeleton`` always counts where there is a
    Kinect: its default, the tracker, changed what such datasets hold."""
    data = config.as_dict()
    for key, table in (("sources", config.sources), ("devices", config.devices)):
        data[key] = [_without_defaults(t) for t in table]
    for values, device in zip(data["devices"], config.devices, strict=True):
        if device.kinect != "none":  # its skeleton was the oracle before the key existed
            values["kinect_skeleton"] = device.kinect_skeleton
    text = json.dumps(data, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


def _without_defaults(table: Any) -> dict[str, Any]:
    """The dataclass ``table`` as JSON data, fields equal to their defaults left out."""
    values = json.loads(json.dumps(asdict(table)))
    return {
        f.name: values[f.name]
        for f in fields(table)
        if f.default is MISSING or getattr(table, f.name) != f.default
    }


def load_config(path: str | Path) -> DatasetConfig:
    """The config in the TOML file ``path``, its memory estimate checked
    (:func:`scripts.dataset.budget.check_budget`).

    Raises:
        ConfigError: an unreadable file, bad TOML, an unknown key, a value of the wrong
            type or range, an empty source, bad split fractions, or more memory than the
            machine has.
    """
    path = Path(path)
    data = read_toml(path)
    try:
        config = from_dict(data)
        check_budget(config)
    except ConfigError as exc:
        raise ConfigError(f"{path}: {exc}") from None
    # A relative mocap folder is relative to the config file, as a scenario's motion path is;
    # a mocap:RELATIVE/PATH one is inside the machine's mocap folder (resolved when planned).
    sources = tuple(
        replace(s, path=str(path.parent / s.path))
        if s.path and not Path(s.path).is_absolute() and not is_mocap_source(s.path)
        else s
        for s in config.sources
    )
    return replace(config, sources=sources)


def from_dict(data: Any) -> DatasetConfig:
    """A checked :class:`DatasetConfig` from plain data (a parsed TOML or a manifest's copy)."""
    devices = data.get("devices") if isinstance(data, Mapping) else None
    if isinstance(devices, list):  # a device set's name defaults to its position
        named = [
            {"name": f"set{k}"} | d if isinstance(d, Mapping) else d for k, d in enumerate(devices)
        ]
        data = {**data, "devices": named}
    config = from_data(DatasetConfig, data)
    config = replace(config, sources=tuple(_source(s, k) for k, s in enumerate(config.sources)))
    for k, device in enumerate(config.devices):
        _device(device, k)
    _splits(config.splits)
    _check(config)
    return config


def _splits(splits: dict[str, float]) -> None:
    unknown = sorted(set(splits) - set(SPLITS))
    if unknown:
        raise ConfigError(f"unknown split {unknown[0]!r} in [splits]; known: {', '.join(SPLITS)}")
    for name, fraction in splits.items():
        if not 0.0 <= fraction <= 1.0:
            raise ConfigError(f"splits.{name} must be a fraction in [0, 1], got {fraction!r}")
    total = sum(splits.values())
    if abs(total - 1.0) > SPLIT_TOLERANCE:
        raise ConfigError(f"split fractions must sum to 1, got {total:g} ({splits})")


def _source(source: SourceConfig, index: int) -> SourceConfig:
    where = f"sources[{index}]"
    if source.kind == "builtin":
        unknown = sorted(set(source.activities) - set(ACTIVITIES))
        if unknown:
            raise ConfigError(
                f"{where}: unknown activity {unknown[0]!r}; built-in: {', '.join(ACTIVITIES)}"
            )
        if not source.activities:
            source = replace(source, activities=ACTIVITIES)
        if source.subjects < 1:
            raise ConfigError(f"{where}.subjects: an empty source: subjects must be at least 1")
    elif not source.path:
        raise ConfigError(f"{where}.path: a mocap source needs a path")
    return source


def _device(device: DeviceSetConfig, index: int) -> None:
    where = f"devices[{index}]"
    if device.fisheye_images != "none" and not device.fisheye:
        raise ConfigError(f"{where}.fisheye_images needs fisheye = true")
    if device.kinect_depth and device.kinect == "none":
        raise ConfigError(f"{where}.kinect_depth needs a kinect sensor")
    if device.kinect_parts and not device.kinect_depth:
        raise ConfigError(f"{where}.kinect_parts needs kinect_depth = true (it is aligned with it)")
    if not device.name.replace("-", "").isalnum():
        raise ConfigError(f"{where}.name must be letters, digits and '-', got {device.name!r}")


def _check(config: DatasetConfig) -> None:
    if not config.sources:
        raise ConfigError("no [[sources]]: a dataset needs at least one motion source")
    if not config.devices:
        raise ConfigError("no [[devices]]: a dataset needs at least one device set")
    names = [d.name for d in config.devices]
    if len(set(names)) != len(names):
        raise ConfigError(f"[[devices]] names must be distinct, got {names}")
