"""A damaged dataset is bad input: a manifest, a shard index entry or a shard member off the
schema gives exit 2 naming the file and the field in every command that reads it (``info``,
``preview``, ``train controllerpose``, the torch ``ShardDataset``); ``verify`` lists a
damaged shard as a problem (exit 1)."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest
from typer.testing import CliRunner

from avatarsim.avatar_models.errors import AvatarsimError
from avatarsim.scripts.cli import app
from avatarsim.scripts.dataset.shards import read_samples, shard_bytes
from avatarsim.scripts.dataset.torch_dataset import ShardDataset

runner = CliRunner()


def _copy(tiny_dataset, tmp_path):
    root = tmp_path / "ds"
    shutil.copytree(tiny_dataset, root)
    return root


def _drop_file(m):
    del m["shards"][0]["file"]
    return m


# (edit of the parsed manifest, the field the error names)
MANIFEST_DAMAGE = {
    "counts as a list": (lambda m: m | {"counts": [1, 2]}, "counts"),
    "an array at the top": (lambda m: [m], "the manifest"),
    "a shard entry without file": (_drop_file, "shards[0].file"),
    "a shard file outside the folder": (
        lambda m: m | {"shards": [m["shards"][0] | {"file": "../../x.tar"}]},
        "shards[0].file",
    ),
    "a split count as text": (
        lambda m: m | {"counts": m["counts"] | {"val": {**m["counts"]["val"], "samples": "2"}}},
        "counts.val.samples",
    ),
    "more samples than the shard's bytes hold": (
        lambda m: m | {"shards": [m["shards"][0] | {"samples": 10**12}]},
        "shards[0].samples",
    ),
}


@pytest.mark.parametrize("damage", MANIFEST_DAMAGE)
@pytest.mark.parametrize("command", ["info", "preview", "verify"])
def test_a_damaged_manifest_is_exit_2_naming_file_and_field(
    tiny_dataset, tmp_path, damage, command
):
    root = _copy(tiny_dataset, tmp_path)
    edit, field = MANIFEST_DAMAGE[damage]
    manifest = root / "manifest.json"
    manifest.write_text(json.dumps(edit(json.loads(manifest.read_text()))))
    extra = ["--out", str(tmp_path / "sheet.png")] if command == "preview" else []
    result = runner.invoke(app, ["dataset", command, str(root), *extra])
    assert result.exit_code == 2, result.output
    reason = " ".join(result.output.split())
    assert str(manifest) in reason and f"{field} is" in reason
    assert not (tmp_path / "sheet.png").exists()


def _retyped(tiny_dataset):
    """The first train shard with one sample's body17 as text (``np.save`` keeps it)."""
    samples = list(read_samples(tiny_dataset / "shards" / "train-000000.tar"))
    entries = []
    for key, sample in samples:
        arrays = {k: v for k, v in sample.items() if k != "json"}
        entries.append((key, arrays, sample["json"]))
    entries[0][1]["body17"] = np.full(entries[0][1]["body17"].shape, "x")
    return shard_bytes(entries), f"sample {samples[0][0]}: body17"


def _reshaped(tiny_dataset):
    samples = list(read_samples(tiny_dataset / "shards" / "train-000000.tar"))
    entries = [(k, {n: v for n, v in s.items() if n != "json"}, s["json"]) for k, s in samples]
    entries[1][1]["vr_pos"] = entries[1][1]["vr_pos"][:, :, :2]
    return shard_bytes(entries), f"sample {samples[1][0]}: vr_pos shape"


def _truncated(tiny_dataset):
    data = (tiny_dataset / "shards" / "train-000000.tar").read_bytes()
    return data[: len(data) // 3 + 100], "train-000000.tar: "


def _one_sample_short(tiny_dataset):
    """The shard cut after its first sample: a valid tar, one sample fewer than listed."""
    samples = list(read_samples(tiny_dataset / "shards" / "train-000000.tar"))
    key, sample = samples[0]
    arrays = {k: v for k, v in sample.items() if k != "json"}
    return shard_bytes([(key, arrays, sample["json"])]), "holds 1 samples"


def _garbage(tiny_dataset):
    return np.random.default_rng(0).bytes(4096), "not a readable shard"


SHARD_DAMAGE = {
    "truncated": _truncated,
    "one sample short": _one_sample_short,
    "garbage": _garbage,
    "re-typed member": _retyped,
    "re-shaped member": _reshaped,
}


@pytest.fixture(params=list(SHARD_DAMAGE))
def damaged_shard(request, tiny_dataset, tmp_path):
    """A copy of the tiny dataset whose first train shard is damaged; the shard's path and
    what the error says."""
    root = _copy(tiny_dataset, tmp_path)
    data, says = SHARD_DAMAGE[request.param](tiny_dataset)
    shard = root / "shards" / "train-000000.tar"
    shard.write_bytes(data)
    return root, shard, says


def test_a_damaged_shard_is_exit_2_in_preview_and_a_problem_in_verify(damaged_shard, tmp_path):
    root, shard, says = damaged_shard
    sheet = tmp_path / "sheet.png"
    result = runner.invoke(
        app, ["dataset", "preview", str(root), "--out", str(sheet), "--samples", "100"]
    )
    assert result.exit_code == 2, result.output
    reason = " ".join(result.output.split())
    assert str(shard) in reason and says in reason
    assert not sheet.exists()
    verify = runner.invoke(app, ["dataset", "verify", str(root)])
    assert verify.exit_code == 1, verify.output
    assert "problem: shards/train-000000.tar: " in " ".join(verify.output.split())


def test_a_damaged_shard_is_a_typed_error_in_the_torch_dataset(damaged_shard):
    root, shard, says = damaged_shard
    with pytest.raises(AvatarsimError) as caught:
        list(ShardDataset(root, split="train"))
    assert str(shard) in str(caught.value) and says in str(caught.value)


def test_a_damaged_shard_is_exit_2_in_train_before_any_epoch(tiny_dataset, tmp_path):
    root = _copy(tiny_dataset, tmp_path)
    data, says = _retyped(tiny_dataset)
    (root / "shards" / "train-000000.tar").write_bytes(data)
    out = tmp_path / "run"
    args = ["train", "controllerpose", "--data", str(root), "--out", str(out)]
    result = runner.invoke(app, [*args, "--max-epochs", "1"])
    assert result.exit_code == 2, result.output
    assert says in " ".join(result.output.split())
    assert not (out / "checkpoint.pt").exists()
