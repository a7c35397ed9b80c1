from __future__ import annotations

import json
import shutil

import pytest

from avatarsim.avatar_models.fileio import sha256_file
from avatarsim.scripts.dataset.manifest import DatasetError
from avatarsim.scripts.dataset.shards import read_samples, shard_bytes
from avatarsim.scripts.dataset.verify import verify_dataset


@pytest.fixture
def copy(tiny_dataset, tmp_path):
    root = tmp_path / "ds"
    shutil.copytree(tiny_dataset, root)
    return root


def _manifest(root):
    return json.loads((root / "manifest.json").read_text())


def _rehash(root, manifest):
    """Make the manifest agree with the shards again, as a careful tamperer would."""
    for entry in manifest["shards"]:
        entry["sha256"] = sha256_file(root / entry["file"])
    (root / "manifest.json").write_text(json.dumps(manifest))


def test_a_generated_dataset_verifies(tiny_dataset):
    report = verify_dataset(tiny_dataset)
    assert report.passed, report.problems
    assert (report.shards, report.samples) == (5, 10)


def test_held_out_subject_moved_into_train_is_a_split_leak(copy):
    manifest = _manifest(copy)
    test_entry = next(e for e in manifest["shards"] if e["split"] == "test")
    train_entry = next(e for e in manifest["shards"] if e["split"] == "train")
    samples = list(read_samples(copy / test_entry["file"]))
    held_out = samples[0][1]["json"]["group"]
    # Rewrite the test shard's samples as train samples in the train shard's place.
    entries = []
    for key, sample in samples:
        meta = {**sample["json"], "split": "train"}
        entries.append((key, {k: v for k, v in sample.items() if k != "json"}, meta))
    (copy / train_entry["file"]).write_bytes(shard_bytes(entries))
    _rehash(copy, manifest)
    report = verify_dataset(copy)
    assert not report.passed
    assert any("split leak" in p and held_out in p for p in report.problems), report.problems


def test_a_manifest_whose_config_moves_a_subject_is_caught(copy):
    manifest = _manifest(copy)
    manifest["config"]["seed"] += 1  # another split assignment
    _rehash(copy, manifest)
    report = verify_dataset(copy)
    assert not report.passed
    assert any("config_hash" in p for p in report.problems)


def test_changed_lost_and_duplicated_shards_are_found(copy):
    manifest = _manifest(copy)
    first, second = manifest["shards"][0], manifest["shards"][1]
    (copy / second["file"]).write_bytes((copy / first["file"]).read_bytes())
    report = verify_dataset(copy)
    problems = " | ".join(report.problems)
    assert "sha256 differs" in problems
    assert "duplicated" in problems and "missing" in problems
    (copy / first["file"]).unlink()
    assert any("missing" in p for p in verify_dataset(copy).problems)


def test_an_unfinished_dataset_is_an_error(copy):
    (copy / "manifest.json").unlink()
    with pytest.raises(DatasetError, match="not finished"):
        verify_dataset(copy)
