"""The plan: every sample of a dataset, in a fixed order, with its split, seeds and shard.

Samples are motion windows x device sets. Motion windows come from each source in turn:
builtin: subjects x activities x ``windows``; mocap: clips (sorted by path) x ``windows``.
Every subject (builtin), clip or performer (mocap) is one *group*; each group is assigned
to exactly one split, so a held-out group never reaches train.

Seeds come from ``numpy.random.SeedSequence(config.seed, spawn_key=...)``, one namespace per
use, so that they depend on the config seed and the index alone (not on the worker count or
on which shards already exist): ``(0, window)`` the motion window, ``(1, sample)`` the
devices' noise, ``(2, source, subject)`` a built-in subject's body, ``(3, source)`` the
assignment of groups to splits. Shards hold samples of one split, in plan order,
``samples_per_shard`` each, named ``{split}-{k:06d}``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from avatarsim.avatar_models.errors import AvatarsimError
from avatarsim.avatar_models.library import MotionLibrary
from avatarsim.avatar_models.mocap_dir import is_mocap_source, resolve_mocap_source
from avatarsim.scripts.dataset.config import SPLITS, ConfigError, DatasetConfig, SourceConfig

WINDOW_SEEDS, DEVICE_SEEDS, SUBJECT_SEEDS, SPLIT_SEEDS = range(4)


def derived_seed(seed: int, *key: int) -> int:
    """A 32-bit seed from ``SeedSequence(seed, spawn_key=key)`` (module docstring)."""
    return int(np.random.SeedSequence(seed, spawn_key=key).generate_state(1)[0])


@dataclass(frozen=True)
class MotionWindow:
    """One window of motion before any device sees it.

    Attributes:
        index: position among all windows of the plan.
        source: index of its ``[[sources]]`` entry.
        kind: ``"builtin"`` or ``"mocap"``.
        group: the unit of splitting (``subject-007``, ``clip:06_06``, ``performer:6``).
        activity: the activity (mocap: the library's label, may be empty).
        subject: builtin: the subject's index in its source; mocap: -1.
        clip: mocap: the clip's path; builtin: empty.
        repeat: which of the ``windows`` of its subject x activity or clip.
        seed: the window's seed (namespace ``(0, index)``).
    """

    index: int
    source: int
    kind: str
    group: str
    activity: str
    subject: int
    clip: str
    repeat: int
    seed: int


@dataclass(frozen=True)
class SampleSpec:
    """One sample: a window recorded by one device set.

    Attributes:
        index: position in the plan; ``key`` its WebDataset key.
        window: the motion window.
        devices: name of the device set.
        split: ``train``, ``val`` or ``test`` (its group's).
        seed: the devices' seed (namespace ``(1, index)``).
    """

    index: int
    key: str
    window: MotionWindow
    devices: str
    split: str
    seed: int


@dataclass(frozen=True)
class ShardSpec:
    """A shard: ``name`` (``{split}-{k:06d}``) and its samples in plan order."""

    name: str
    split: str
    samples: tuple[SampleSpec, ...]


def assign_splits(groups: list[str], fractions: dict[str, float], seed: int) -> dict[str, str]:
    """Each of ``groups`` (distinct) -> a split, in proportion to ``fractions``.

    Counts are floors of ``fraction * n`` with the rest given by largest remainder, after
    every split with a positive fraction gets one group where there are enough; which
    groups go where is a permutation drawn from ``seed``.
    """
    n = len(groups)
    wanted = np.array([fractions.get(s, 0.0) for s in SPLITS]) * n  # a split left out: 0
    counts = np.floor(wanted).astype(int)
    positive = wanted > 0
    if n >= positive.sum():
        counts = np.where(positive & (counts == 0), 1, counts)
    while counts.sum() > n:  # the minimum of one took groups from the largest split
        counts[np.argmax(counts)] -= 1
    for k in np.argsort(-(wanted - np.floor(wanted)), kind="stable")[: n - counts.sum()]:
        counts[k] += 1
    order = np.random.default_rng(seed).permutation(n)
    ordered = [sorted(groups)[i] for i in order]
    bounds = np.concatenate([[0], np.cumsum(counts)])
    return {g: SPLITS[k] for k in range(len(SPLITS)) for g in ordered[bounds[k] : bounds[k + 1]]}


def mocap_clips(source: SourceConfig) -> list:
    """The library clips of a mocap source, filtered by its activities, sorted by path.

    Raises:
        ConfigError: a missing folder or clip, no mocap folder for a ``mocap:`` path, no
        clips, or performers unknown with
        ``split_by = "performer"``.
    """
    try:
        mocap = is_mocap_source(source.path)
        folder = resolve_mocap_source(source.path) if mocap else Path(source.path)
    except AvatarsimError as exc:
        raise ConfigError(f"mocap source {source.path}: {exc}") from None
    one = folder if folder.is_file() else None  # a single clip
    if one is None and not folder.is_dir():
        raise ConfigError(f"mocap source {folder}: no such folder or clip")
    try:
        library = MotionLibrary.index(folder.parent if one else folder)
    except AvatarsimError as exc:
        raise ConfigError(f"mocap source {folder}: {exc}") from None
    clips = sorted(
        (
            c
            for c in library
            if (not source.activities or c.activity in source.activities)
            and (one is None or Path(c.path) == one)
        ),
        key=lambda c: str(c.path),
    )
    if not clips:
        raise ConfigError(f"mocap source {folder}: an empty source (no clips match)")
    if source.split_by == "performer":
        unknown = [c.name for c in clips if c.subject is None]
        if unknown:
            raise ConfigError(
                f"mocap source {folder}: performer unknown for {unknown[0]} (and "
                f"{len(unknown) - 1} more); use split_by = 'clip'"
            )
    return clips


def _source_windows(config: DatasetConfig, k: int, start: int) -> tuple[list[MotionWindow], dict]:
    """The windows of source ``k`` (indices from ``start``) and its groups' splits."""
    source = config.sources[k]
    items = []  # (group, activity, subject, clip)
    if source.kind == "builtin":
        for subject in range(source.subjects):
            for activity in source.activities:
                items.append((f"subject-{subject:03d}", activity, subject, ""))
    else:
        for clip in mocap_clips(source):
            by_clip = source.split_by == "clip"
            group = f"clip:{clip.name}" if by_clip else f"performer:{clip.subject}"
            items.append((group, clip.activity or "", -1, str(clip.path)))
    windows = []
    for group, activity, subject, clip in items:
        for repeat in range(source.windows):
            index = start + len(windows)
            seed = derived_seed(config.seed, WINDOW_SEEDS, index)
            windows.append(
                MotionWindow(index, k, source.kind, group, activity, subject, clip, repeat, seed)
            )
    groups = sorted({w.group for w in windows})
    splits = assign_splits(groups, config.splits, derived_seed(config.seed, SPLIT_SEEDS, k))
    return windows, splits


def plan_samples(config: DatasetConfig) -> list[SampleSpec]:
    """Every sample of ``config``, in plan order (module docstring)."""
    samples: list[SampleSpec] = []
    n_windows = 0
    for k in range(len(config.sources)):
        windows, splits = _source_windows(config, k, n_windows)
        n_windows += len(windows)
        for window in windows:
            for devices in config.devices:
                index = len(samples)
                seed = derived_seed(config.seed, DEVICE_SEEDS, index)
                key = f"s{index:07d}"
                samples.append(
                    SampleSpec(index, key, window, devices.name, splits[window.group], seed)
                )
    return samples


def plan_shards(config: DatasetConfig, samples: list[SampleSpec]) -> list[ShardSpec]:
    """The shards of ``samples``: per split, in plan order, ``samples_per_shard`` each."""
    shards = []
    size = config.samples_per_shard
    for split in SPLITS:
        mine = [s for s in samples if s.split == split]
        for k in range(0, len(mine), size):
            shards.append(ShardSpec(f"{split}-{k // size:06d}", split, tuple(mine[k : k + size])))
    return shards


def subject_seed(config: DatasetConfig, window: MotionWindow) -> int:
    """The seed of a built-in window's subject (namespace ``(2, source, subject)``)."""
    return derived_seed(config.seed, SUBJECT_SEEDS, window.source, window.subject)
