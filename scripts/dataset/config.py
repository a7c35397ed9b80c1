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
import tomllib
from dataclasses import MISSING, asdict, dataclass, field, fields, replace
from pathlib import Path
from typing import Any

from avatar_models.errors import AvatarsimError
from avatar_models.generator import ACTIVITIES
from render_cams.fisheye.device import SCALE_RANGE

SPLITS = ("train", "val", "test")
VR_NOISE = ("none", "realistic")
KINECT_SENSORS = ("none", "kinect-v2", "azure-kinect")
IMAGE_FORMATS = ("none", "jpeg", "png")
MOCAP_SPLIT_BY = ("clip", "performer")
SPLIT_TOLERANCE = 1e-6


class ConfigError(AvatarsimError):
    """A dataset config that cannot be used (path and reason)."""


@dataclass(frozen=True)
class WindowConfig:
    """One sample is one window of a clip: ``seconds`` long, ground truth at ``fps``."""

    seconds: float = 4.0
    fps: float = 30.0


@dataclass(frozen=True)
class SourceConfig:
    """A motion source.

    Attributes:
        kind: ``"builtin"`` (the procedural generator) or ``"mocap"`` (a folder, indexed by
            :class:`avatar_models.library.MotionLibrary`).
        activities: activities to use (builtin: default all; mocap: a filter, default all).
        subjects: builtin: number of sampled subjects.
        windows: windows per subject x activity (builtin) or per clip (mocap).
        path: mocap: the folder (relative to the config file's folder when read by
            :func:`load_config`).
        split_by: mocap: ``"clip"`` or ``"performer"`` (the library's subject label).
    """

    kind: str
    activities: tuple[str, ...] = ()
    subjects: int = 0
    windows: int = 1
    path: str = ""
    split_by: str = "clip"


@dataclass(frozen=True)
class DeviceSetConfig:
    """What one sample records of its window.

    Attributes:
        name: the device set's name (part of every sample key).
        vr: headset + controllers at 90 Hz; ``trackers`` adds the Vive trackers.
        vr_noise: ``"none"`` or ``"realistic"`` (scripts.stages.devices.REALISTIC_NOISE).
        fisheye: projected 2D keypoints of the controller cameras.
        fisheye_images: ``"none"``, ``"jpeg"`` or ``"png"``: the cameras' rendered images
            (needs ``fisheye``).
        kinect: ``"none"``, ``"kinect-v2"`` or ``"azure-kinect"``: the skeleton with
            tracking states.
        kinect_depth: the Kinect's 16-bit depth images in millimetres, PNG (needs a
            ``kinect``).
        image_stride: images and depth of every ``image_stride``-th camera frame (rendering
            is most of a sample's time; 3 gives 10 Hz at the cameras' 30 Hz).
        image_scale: fisheye image size factor (1: 640 x 480).
        physics: per-frame physics labels (contact, penetration, skate).
    """

    name: str
    vr: bool = True
    trackers: bool = False
    vr_noise: str = "none"
    fisheye: bool = True
    fisheye_images: str = "none"
    kinect: str = "none"
    kinect_depth: bool = False
    image_stride: int = 3
    image_scale: float = 0.5
    physics: bool = True


@dataclass(frozen=True)
class DatasetConfig:
    """A whole dataset config (module docstring)."""

    name: str
    seed: int = 0
    samples_per_shard: int = 64
    window: WindowConfig = field(default_factory=WindowConfig)
    splits: dict[str, float] = field(
        default_factory=lambda: dict(zip(SPLITS, (0.8, 0.1, 0.1), strict=True))
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
    datasets made before it, unchanged."""
    data = config.as_dict()
    for key, table in (("sources", config.sources), ("devices", config.devices)):
        data[key] = [_without_defaults(t) for t in table]
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
    """The config in the TOML file ``path``.

    Raises:
        ConfigError: unreadable file, bad TOML, unknown key, empty source, bad split
        fractions or values.
    """
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read: {exc.strerror or exc}") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{path}: not valid TOML: {exc}") from None
    try:
        config = from_dict(data)
    except ConfigError as exc:
        raise ConfigError(f"{path}: {exc}") from None
    # A relative mocap folder is relative to the config file, as a scenario's motion path is.
    sources = tuple(
        replace(s, path=str(path.parent / s.path))
        if s.path and not Path(s.path).is_absolute()
        else s
        for s in config.sources
    )
    return replace(config, sources=sources)


def from_dict(data: dict[str, Any]) -> DatasetConfig:
    """A checked :class:`DatasetConfig` from plain data (a parsed TOML or a manifest's copy)."""
    top = _known(data, DatasetConfig, "the config")
    if "name" not in top:
        raise ConfigError("the config needs a name")
    window = WindowConfig(**_known(top.pop("window", {}), WindowConfig, "[window]"))
    splits = _splits(top.pop("splits", DatasetConfig(name="").splits))
    sources = tuple(_source(s, k) for k, s in enumerate(_tables(top.pop("sources", []))))
    devices = tuple(_device(d, k) for k, d in enumerate(_tables(top.pop("devices", []))))
    config = DatasetConfig(window=window, splits=splits, sources=sources, devices=devices, **top)
    _check(config)
    return config


def _known(data: Any, cls: type, where: str) -> dict[str, Any]:
    if not isinstance(data, dict):
        raise ConfigError(f"{where} must be a table, got {type(data).__name__}")
    names = {f.name for f in fields(cls)}
    unknown = sorted(set(data) - names)
    if unknown:
        raise ConfigError(
            f"unknown key {unknown[0]!r} in {where}; known: {', '.join(sorted(names))}"
        )
    return dict(data)


def _tables(value: Any) -> list[dict]:
    if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
        raise ConfigError("[[sources]] and [[devices]] must be arrays of tables")
    return value


def _splits(value: Any) -> dict[str, float]:
    if not isinstance(value, dict):
        raise ConfigError(f"[splits] must be a table, got {type(value).__name__}")
    splits = dict(value)
    unknown = sorted(set(splits) - set(SPLITS))
    if unknown:
        raise ConfigError(f"unknown split {unknown[0]!r} in [splits]; known: {', '.join(SPLITS)}")
    out = {}
    for name in SPLITS:
        fraction = splits.get(name, 0.0)
        if not isinstance(fraction, int | float) or not 0.0 <= fraction <= 1.0:
            raise ConfigError(f"split {name} must be a fraction in [0, 1], got {fraction!r}")
        out[name] = float(fraction)
    if abs(sum(out.values()) - 1.0) > SPLIT_TOLERANCE:
        raise ConfigError(f"split fractions must sum to 1, got {sum(out.values()):g} ({out})")
    return out


def _source(data: dict, index: int) -> SourceConfig:
    where = f"[[sources]] #{index + 1}"
    values = _known(data, SourceConfig, where)
    values["activities"] = tuple(values.get("activities", ()))
    source = SourceConfig(**values)
    if source.kind == "builtin":
        unknown = sorted(set(source.activities) - set(ACTIVITIES))
        if unknown:
            raise ConfigError(
                f"{where}: unknown activity {unknown[0]!r}; built-in: {', '.join(ACTIVITIES)}"
            )
        if not source.activities:
            source = replace(source, activities=ACTIVITIES)
        if source.subjects < 1:
            raise ConfigError(f"{where}: an empty source: subjects must be at least 1")
    elif source.kind == "mocap":
        if not source.path:
            raise ConfigError(f"{where}: a mocap source needs a path")
        if source.split_by not in MOCAP_SPLIT_BY:
            raise ConfigError(f"{where}: split_by must be one of {', '.join(MOCAP_SPLIT_BY)}")
    else:
        raise ConfigError(f"{where}: kind must be 'builtin' or 'mocap', got {source.kind!r}")
    if source.windows < 1:
        raise ConfigError(f"{where}: an empty source: windows must be at least 1")
    return source


def _device(data: dict, index: int) -> DeviceSetConfig:
    where = f"[[devices]] #{index + 1}"
    device = DeviceSetConfig(**_known({"name": f"set{index}"} | data, DeviceSetConfig, where))
    if device.vr_noise not in VR_NOISE:
        raise ConfigError(f"{where}: vr_noise must be one of {', '.join(VR_NOISE)}")
    if device.kinect not in KINECT_SENSORS:
        raise ConfigError(f"{where}: kinect must be one of {', '.join(KINECT_SENSORS)}")
    if device.fisheye_images not in IMAGE_FORMATS:
        raise ConfigError(f"{where}: fisheye_images must be one of {', '.join(IMAGE_FORMATS)}")
    if device.fisheye_images != "none" and not device.fisheye:
        raise ConfigError(f"{where}: fisheye_images needs fisheye = true")
    if device.kinect_depth and device.kinect == "none":
        raise ConfigError(f"{where}: kinect_depth needs a kinect sensor")
    if not isinstance(device.image_stride, int) or device.image_stride < 1:
        raise ConfigError(f"{where}: image_stride must be an integer >= 1")
    lo, hi = SCALE_RANGE
    if not (isinstance(device.image_scale, int | float) and lo <= device.image_scale <= hi):
        raise ConfigError(f"{where}: image_scale must be in [{lo:g}, {hi:g}]")
    if not device.name.replace("-", "").isalnum():
        raise ConfigError(f"{where}: name must be letters, digits and '-', got {device.name!r}")
    return device


def _check(config: DatasetConfig) -> None:
    if not isinstance(config.seed, int) or config.seed < 0:
        raise ConfigError(f"seed must be an integer >= 0, got {config.seed!r}")
    if not isinstance(config.samples_per_shard, int) or config.samples_per_shard < 1:
        raise ConfigError(f"samples_per_shard must be at least 1, got {config.samples_per_shard}")
    if not (config.window.seconds > 0 and config.window.fps > 0):
        raise ConfigError(f"[window] seconds and fps must be positive, got {config.window}")
    if not config.sources:
        raise ConfigError("no [[sources]]: a dataset needs at least one motion source")
    if not config.devices:
        raise ConfigError("no [[devices]]: a dataset needs at least one device set")
    names = [d.name for d in config.devices]
    if len(set(names)) != len(names):
        raise ConfigError(f"[[devices]] names must be distinct, got {names}")
