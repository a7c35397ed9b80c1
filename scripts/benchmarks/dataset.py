"""Dataset generation and reading throughput.

Rows, each against a baseline run in this process:

- ``dataset_generate[keypoints]``: samples/s on one core (local executor, one worker) of
  VR + projected fisheye keypoints + physics labels, 4 s windows at 30 Hz as
  ``controllerpose-small``; baseline: the same samples' real-time rate (a 4 s window per
  4 s), so the ratio says how many times faster than real time one core makes them.
- ``dataset_generate[images]``: the same with fisheye JPEGs and Kinect v2 depth every third
  frame at half size; baseline: keypoints only (the ratio is what images cost).
- ``dataset_ray[2 vs 1 workers]``: samples/s with ``--executor ray`` and 2 workers; baseline:
  1 worker, on one local Ray instance started once (its start-up is not timed). Our aim
  is 1.8x or more; the machine's free cores bound it.
- ``dataset_read[DataLoader 2 workers]``: samples/s streamed from the shards through
  ``ShardDataset.loader`` (a torch ``DataLoader``) with 2 workers; baseline: no workers.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from avatarsim.scripts.benchmarks import BenchRow
from avatarsim.scripts.dataset.config import DatasetConfig, from_dict
from avatarsim.scripts.dataset.runner import generate

ACTIVITIES = ["walk", "box", "wave", "kick"]  # a planned gait, arms, a balance: mixed costs
KEYPOINTS = {"name": "kp", "vr_noise": "realistic"}
IMAGES = KEYPOINTS | {
    "name": "img",
    "fisheye_images": "jpeg",
    "kinect": "kinect-v2",
    "kinect_depth": True,
}


def bench_config(devices: dict, subjects: int, seconds: float) -> DatasetConfig:
    """One sample per shard (so that executors can spread them), ``subjects`` x 4 activities."""
    return from_dict(
        {
            "name": f"bench-{devices['name']}",
            "samples_per_shard": 1,
            "window": {"seconds": seconds, "fps": 30.0},
            "splits": {"train": 1.0},
            "sources": [{"kind": "builtin", "activities": ACTIVITIES, "subjects": subjects}],
            "devices": [devices],
        }
    )


def samples_per_s(config: DatasetConfig, folder: Path, **executor) -> float:
    """Samples/s of generating ``config`` into a new ``folder`` (wall time)."""
    result = generate(config, folder, **executor)
    return result.made_samples / result.seconds


def _read_rate(root: Path, workers: int, epochs: int) -> float:
    """Samples/s over ``epochs`` passes of :meth:`ShardDataset.loader`, worker start-up
    included once (persistent workers, as a training loop keeps them)."""
    from avatarsim.scripts.dataset.torch_dataset import ShardDataset

    data = ShardDataset(root, "train", shuffle_buffer=8, seed=0)
    loader = data.loader(num_workers=workers)
    start = time.perf_counter()
    n = 0
    for epoch in range(epochs):
        data.set_epoch(epoch)
        n += sum(1 for _ in loader)
    return n / (time.perf_counter() - start)


def _ray_rows(config: DatasetConfig, folder: Path) -> list[BenchRow]:
    try:
        import ray
    except ImportError:
        return []
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, configure_logging=False)
    try:
        samples_per_s(config, folder / "warm", executor="ray", workers=2)  # workers imported
        one = samples_per_s(config, folder / "ray1", executor="ray", workers=1)
        two = samples_per_s(config, folder / "ray2", executor="ray", workers=2)
    finally:
        ray.shutdown()
    note = f"{len(list((folder / 'ray2' / 'shards').glob('*.tar')))} one-sample shards"
    return [BenchRow("dataset_ray[2 vs 1 workers]", "samples/s", two, one, "1 worker", note)]


def run(quick: bool = False, mocap: Path | None = None) -> list[BenchRow]:
    """The rows of the module docstring."""
    seconds = 1.0 if quick else 4.0
    subjects = 1 if quick else 2
    keypoints = bench_config(KEYPOINTS, subjects, seconds)
    images = bench_config(IMAGES, 1, 1.0 if quick else 2.0)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        kp_rate = samples_per_s(keypoints, folder / "kp")
        kp_images_rate = samples_per_s(images, folder / "img")
        same_windows = bench_config(KEYPOINTS, 1, images.window.seconds)
        kp_same_rate = samples_per_s(same_windows, folder / "k2")
        rows = [
            BenchRow(
                "dataset_generate[keypoints]",
                "samples/s",
                kp_rate,
                1.0 / seconds,
                "real time",
                f"{seconds:g} s windows, 1 core, VR + fisheye keypoints + physics",
            ),
            BenchRow(
                "dataset_generate[images]",
                "samples/s",
                kp_images_rate,
                kp_same_rate,
                "keypoints only",
                f"{images.window.seconds:g} s windows, 1 core, + fisheye JPEG and Kinect "
                "depth every 3rd frame",
            ),
            *_ray_rows(keypoints, folder),
        ]
        epochs = 5 if quick else 20
        rows.append(
            BenchRow(
                "dataset_read[DataLoader 2 workers]",
                "samples/s",
                _read_rate(folder / "kp", 2, epochs),
                _read_rate(folder / "kp", 0, epochs),
                "no workers",
                f"ShardDataset, shuffle buffer 8, {epochs} epochs of the keypoints row's shards",
            )
        )
    return rows
