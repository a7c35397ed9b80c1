from __future__ import annotations

import errno
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from avatarsim.scripts.dataset import runner as runner_module
from avatarsim.scripts.dataset.config import load_config
from avatarsim.scripts.dataset.executors import ExecutorError
from avatarsim.scripts.dataset.manifest import DatasetError
from avatarsim.scripts.dataset.runner import generate
from avatarsim.scripts.dataset.shards import read_samples
from avatarsim.scripts.dataset.verify import verify_dataset
from tests.scripts.dataset.builders import TINY, tree_bytes, write_config

REPO = Path(__file__).resolve().parents[3]


def test_two_workers_write_the_same_bytes_as_one(tiny_dataset, tiny_config_path, tmp_path):
    result = generate(load_config(tiny_config_path), tmp_path / "ds", workers=2)
    assert result.made == result.shards == 5
    assert tree_bytes(tmp_path / "ds") == tree_bytes(tiny_dataset)


def test_ray_executor_writes_the_same_bytes_as_local(
    local_ray, tiny_dataset, tiny_config_path, tmp_path
):
    result = generate(load_config(tiny_config_path), tmp_path / "ds", workers=2, executor="ray")
    assert result.made == 5
    assert tree_bytes(tmp_path / "ds") == tree_bytes(tiny_dataset)


def test_a_full_disk_stops_cleanly_and_the_next_run_resumes(
    tiny_dataset, tiny_config_path, tmp_path, monkeypatch
):
    """The third shard write fails with ENOSPC: a DatasetError, two whole shards with their
    sidecars, no temporary file, no manifest; then a run with space finishes the same bytes."""
    real_write = runner_module.write_atomic
    writes = []

    def full_after_two(path, data):
        writes.append(path)
        if len(writes) > 2:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
        return real_write(path, data)

    monkeypatch.setattr(runner_module, "write_atomic", full_after_two)
    root = tmp_path / "ds"
    config = load_config(tiny_config_path)
    with pytest.raises(DatasetError, match="No space left.*run generate again to resume"):
        generate(config, root)
    kept = sorted(p.name for p in (root / "shards").iterdir())
    shards = ["train-000000", "train-000001"]  # one worker makes them in plan order
    assert kept == sorted(f"{name}.{ext}" for name in shards for ext in ("json", "tar"))
    assert not list(root.rglob("*.tmp")) and not (root / "manifest.json").exists()
    monkeypatch.setattr(runner_module, "write_atomic", real_write)
    assert generate(config, root).made == 3
    assert tree_bytes(root) == tree_bytes(tiny_dataset)


def test_a_bad_executor_writes_nothing(tiny_config_path, tmp_path):
    with pytest.raises(ExecutorError, match="--address"):
        generate(load_config(tiny_config_path), tmp_path / "ds", address="auto")
    assert not (tmp_path / "ds").exists()


def test_resume_remakes_only_what_is_missing_or_wrong(tiny_dataset, tiny_config_path, tmp_path):
    root = tmp_path / "ds"
    root.mkdir()
    for name, data in tree_bytes(tiny_dataset).items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_bytes(data)
    (root / "manifest.json").unlink()
    (root / "shards" / "train-000001.tar").unlink()  # lost
    (root / "shards" / "val-000000.tar").write_bytes(b"half a shard")  # torn
    (root / "shards" / ".test-000000.tar.abc.tmp").write_bytes(b"left by a kill")
    result = generate(load_config(tiny_config_path), root, workers=1)
    assert result.made == 2
    assert tree_bytes(root) == tree_bytes(tiny_dataset)


def test_foreign_or_other_config_folders_are_refused(tiny_dataset, tiny_config_path, tmp_path):
    before = tree_bytes(tiny_dataset)
    with pytest.raises(DatasetError, match="another config or seed"):
        generate(load_config(tiny_config_path).with_seed(4), tiny_dataset)
    assert tree_bytes(tiny_dataset) == before
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(DatasetError, match="holds no dataset"):
        generate(load_config(tiny_config_path), tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"]


def _generate_cmd(config: Path, out: Path) -> list[str]:
    return [
        sys.executable,
        "-m",
        "avatarsim.scripts.cli",
        "dataset",
        "generate",
        str(config),
        "--out",
        str(out),
    ]


# 20 kills get a dataset of 20 one-sample shards, so that most of them land mid-run.
MANY_SHARDS = {"samples_per_shard": 1, "sources": [{**TINY["sources"][0], "subjects": 10}]}


@pytest.mark.parametrize(
    "kills, changes", [(3, {}), pytest.param(20, MANY_SHARDS, marks=pytest.mark.slow)]
)
def test_kill_9_at_random_moments_then_resume_is_byte_identical(
    tiny_dataset, tmp_path, kills, changes
):
    """``kill -9`` the generator ``kills`` times, each at a random moment while it works
    (once it has written a shard more than the last run left, plus 0-0.5 s: a time of its
    own would let a fast machine finish first), then let it finish: the same bytes as an
    uninterrupted run, and ``verify`` passes."""
    config_path = write_config(tmp_path / "c.toml", **changes)
    expected = tiny_dataset
    if changes:
        expected = tmp_path / "expected"
        generate(load_config(config_path), expected)
    n_shards = len(list((expected / "shards").glob("*.tar")))
    rng = random.Random(kills)
    out = tmp_path / "ds"
    env = {**os.environ, "PYTHONPATH": str(REPO)}

    def shards_written() -> int:
        return len(list((out / "shards").glob("*.tar")))

    shards_seen = []
    for _ in range(kills):
        before = shards_written()
        begun = time.monotonic()
        proc = subprocess.Popen(
            _generate_cmd(config_path, out),
            cwd=REPO,
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        while proc.poll() is None and shards_written() <= before:
            assert time.monotonic() - begun < 120
            time.sleep(0.01)
        time.sleep(rng.uniform(0.0, 0.5))
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        shards_seen.append(shards_written())
    assert any(0 < n < n_shards for n in shards_seen), shards_seen  # some kills cut the work short
    done = subprocess.run(
        _generate_cmd(config_path, out), cwd=REPO, env=env, capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    assert tree_bytes(out) == tree_bytes(expected), shards_seen
    assert verify_dataset(out).passed
    print(f"shards written at each of the {kills} kills: {shards_seen}")


@pytest.mark.mocap
def test_a_mocap_dataset_split_by_clip_verifies(mocap_dir, tmp_path):
    source = {"kind": "mocap", "path": str(mocap_dir / "cmu"), "activities": ["running"]}
    config = load_config(write_config(tmp_path / "c.toml", sources=[source]))
    result = generate(config, tmp_path / "ds")
    counts = result.manifest["counts"]
    assert result.samples == 3  # CLIPS.md: 3 running clips
    train, held_out = (
        set(counts["train"]["groups"]),
        {*counts["val"]["groups"], *counts["test"]["groups"]},
    )
    assert held_out and not train & held_out
    assert all(g.startswith("clip:") for g in train | held_out)
    assert verify_dataset(tmp_path / "ds").passed


def _bandai_subset(mocap_dir: Path, folder: Path, names: list[str]) -> Path:
    """A Bandai dataset folder of a few clips: links to its ``cfg`` labels and to each clip
    with its ``.json`` (the real files, read in place, not copied)."""
    source = mocap_dir / "bandai" / "dataset-2"
    (folder / "data").mkdir(parents=True)
    (folder / "cfg").symlink_to(source / "cfg")
    for name in names:
        for ext in (".bvh", ".json"):
            (folder / "data" / f"{name}{ext}").symlink_to(source / "data" / f"{name}{ext}")
    return folder


@pytest.mark.mocap
@pytest.mark.parametrize("dataset", ["dataset-1", "dataset-2"])
def test_a_bandai_dataset_split_by_clip_verifies(mocap_dir, tmp_path, dataset):
    """Three real clips of each Bandai set (a foreign rig: retargeted onto the humanoid),
    one per split; dataset-1 through its own folder and an activity filter (one take each
    of kick, respond and dance-short), dataset-2 through a folder of three of its clips."""
    if dataset == "dataset-1":
        path = mocap_dir / "bandai" / "dataset-1"
        activities = ["kick", "respond", "dance-short"]
    else:
        names = [f"dataset-2_{c}_normal_001" for c in ("walk", "run", "wave-left-hand")]
        path, activities = _bandai_subset(mocap_dir, tmp_path / "d2", names), []
    source = {"kind": "mocap", "path": str(path), "activities": activities}
    # Half-second windows: retargeting (IK per frame) is most of a Bandai sample's time.
    window = {"seconds": 0.5, "fps": 30.0}
    config = load_config(write_config(tmp_path / "c.toml", sources=[source], window=window))
    result = generate(config, tmp_path / "ds")
    counts = result.manifest["counts"]
    assert result.samples == 3 and all(counts[s]["samples"] == 1 for s in counts)
    assert result.frames == 3 * 16  # 0.5 s at 30 Hz, both ends: every clip is longer
    assert verify_dataset(tmp_path / "ds").passed
    sample = next(read_samples(tmp_path / "ds" / result.manifest["shards"][0]["file"]))[1]
    assert sample["json"]["body"]["retargeted"] and sample["json"]["provenance"]["clip"]
