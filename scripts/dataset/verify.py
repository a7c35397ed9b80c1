"""``dataset verify``: a dataset is what its manifest and config say, whole and without leaks.

Checked against facts recomputed from the config (the plan), not against the manifest's own
claims: every shard's sha256 and size; every planned sample present exactly once, in a shard
of its split, with its group and split; no group (subject, clip, performer) in two splits,
and none held out of train found in a train shard; samples and frames per split as counted.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

from avatarsim.avatar_models.fileio import sha256_file
from avatarsim.scripts.dataset.config import SPLITS, ConfigError, config_hash, from_dict
from avatarsim.scripts.dataset.manifest import STATE_FILE, read_json, read_manifest
from avatarsim.scripts.dataset.plan import plan_samples
from avatarsim.scripts.dataset.schema import DatasetError, checked_samples
from avatarsim.scripts.dataset.shards import ShardError

MAX_LISTED = 20  # problems listed one by one; more are counted


@dataclass
class VerifyReport:
    """Problems found (empty: the dataset is sound) and what was read."""

    problems: list[str] = field(default_factory=list)
    shards: int = 0
    samples: int = 0
    frames: int = 0

    @property
    def passed(self) -> bool:
        return not self.problems


def verify_dataset(root: Path) -> VerifyReport:
    """Check the dataset in ``root`` (module docstring).

    Raises:
        DatasetError: no finished dataset in ``root``, or a manifest off the schema
            (:func:`scripts.dataset.schema.check_manifest`); a shard or sample off it is a
            problem found.
    """
    manifest = read_manifest(root)
    report = VerifyReport()
    problems = report.problems
    try:
        config = from_dict(manifest["config"])
    except (ConfigError, KeyError) as exc:
        return VerifyReport([f"manifest config unusable: {exc}"])
    chash = config_hash(config)
    if manifest.get("config_hash") != chash:
        problems.append("manifest config_hash does not match its config")
    started = read_json(root / STATE_FILE, "dataset state") if (root / STATE_FILE).is_file() else {}
    if started and (not isinstance(started, dict) or started.get("config_hash") != chash):
        problems.append("manifest config differs from the one generation started with")
    planned = {s.key: s for s in plan_samples(config)}
    held_out = {s.window.group for s in planned.values() if s.split != "train"}
    seen: Counter[str] = Counter()
    per_split = {split: Counter() for split in SPLITS}
    group_splits: dict[str, set[str]] = {}
    for entry in manifest.get("shards", []):
        path = root / entry["file"]
        if not path.is_file():
            problems.append(f"{entry['file']}: missing")
            continue
        if sha256_file(path) != entry["sha256"]:
            problems.append(f"{entry['file']}: sha256 differs from the manifest")
        report.shards += 1
        samples = frames = 0
        try:
            for key, sample in checked_samples(path):  # counts compared below
                meta = sample.get("json", {})
                samples += 1
                frames += int(meta.get("frames", 0))
                seen[key] += 1
                group, split = meta.get("group"), meta.get("split")
                group_splits.setdefault(group, set()).add(entry["split"])
                plan = planned.get(key)
                if plan is None:
                    problems.append(f"{entry['file']}: sample {key} is not in the plan")
                    continue
                if entry["split"] == "train" and group in held_out:
                    problems.append(f"split leak: held-out {group} ({key}) in train shard")
                if (group, split) != (plan.window.group, plan.split) or split != entry["split"]:
                    problems.append(
                        f"{entry['file']}: sample {key} is {group}/{split} in a "
                        f"{entry['split']} shard; planned {plan.window.group}/{plan.split}"
                    )
        except (ShardError, DatasetError, OSError) as exc:
            problems.append(f"{entry['file']}: unreadable: {exc}")
        if (samples, frames) != (entry["samples"], entry["frames"]):
            problems.append(
                f"{entry['file']}: {samples} samples, {frames} frames; manifest says "
                f"{entry['samples']}, {entry['frames']}"
            )
        per_split[entry["split"]].update(samples=samples, frames=frames)
        report.samples += samples
        report.frames += frames
    duplicated = sorted(k for k, n in seen.items() if n > 1)
    lost = sorted(set(planned) - set(seen))
    if duplicated:
        problems.append(f"{len(duplicated)} sample(s) duplicated, e.g. {duplicated[0]}")
    if lost:
        problems.append(f"{len(lost)} planned sample(s) missing, e.g. {lost[0]}")
    for group, splits in sorted(group_splits.items(), key=lambda kv: str(kv[0])):
        if len(splits) > 1:
            problems.append(f"split leak: {group} is in {', '.join(sorted(splits))}")
    for split in SPLITS:
        claimed = manifest.get("counts", {}).get(split, {})
        counted = per_split[split]
        if (claimed.get("samples"), claimed.get("frames")) != (
            counted["samples"],
            counted["frames"],
        ):
            problems.append(
                f"counts of {split}: manifest {claimed.get('samples')} samples / "
                f"{claimed.get('frames')} frames, shards hold {counted['samples']} / "
                f"{counted['frames']}"
            )
    if len(problems) > MAX_LISTED:
        report.problems = [*problems[:MAX_LISTED], f"... and {len(problems) - MAX_LISTED} more"]
    return report
