"""``dataset preview``: a picture sheet of random samples with the ground-truth skeleton drawn.

Each panel is one sample at one frame, both drawn from ``seed``. With a fisheye channel it
shows the controller camera that sees the most joints then: its rendered image when the
sample has images (at a rendered frame), the image frame, the body17
keypoints (filled where ``in_view``, hollow where not) and the skeleton between them, so a
wrong projection, a mirrored camera or a swapped side shows at a glance. Without one it
shows the 3D ground truth from the side (X forward, Z up). The title names the key,
activity, split and camera.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import numpy as np

from avatarsim.avatar_models.body17 import INDEX
from avatarsim.scripts.dataset.channels import IMAGE_SUFFIX
from avatarsim.scripts.dataset.manifest import DatasetError, read_manifest
from avatarsim.scripts.dataset.schema import checked_samples
from avatarsim.scripts.output_file import write_output

# body17 drawn as lines, coloured by side: trunk, then each arm and leg outwards.
TRUNK_LINES = (("head", "neck"), ("neck", "pelvis"))
LIMB_LINES = (
    ("neck", "{s}_shoulder"),
    ("{s}_shoulder", "{s}_elbow"),
    ("{s}_elbow", "{s}_wrist"),
    ("pelvis", "{s}_hip"),
    ("{s}_hip", "{s}_knee"),
    ("{s}_knee", "{s}_ankle"),
    ("{s}_ankle", "{s}_foot"),
)
SIDE_COLOURS = {"l": "tab:blue", "r": "tab:red"}
SKELETON_LINES = (
    *((INDEX[a], INDEX[b], "0.3") for a, b in TRUNK_LINES),
    *(
        (INDEX[a.format(s=side)], INDEX[b.format(s=side)], colour)
        for side, colour in SIDE_COLOURS.items()
        for a, b in LIMB_LINES
    ),
)


def pick_samples(root: Path, count: int, seed: int, split: str | None) -> list[tuple[str, dict]]:
    """``count`` samples drawn without replacement (all when fewer), in plan order.

    Raises:
        DatasetError: no finished dataset in ``root``, or no sample in ``split``.
    """
    manifest = read_manifest(root)
    shards = [s for s in manifest["shards"] if split is None or s["split"] == split]
    slots = [(k, i) for k, s in enumerate(shards) for i in range(s["samples"])]
    if not slots:
        raise DatasetError(f"{root}: no samples{f' in split {split}' if split else ''}")
    rng = np.random.default_rng(seed)
    chosen = sorted(rng.choice(len(slots), size=min(count, len(slots)), replace=False))
    wanted: dict[int, set[int]] = {}
    for k, i in (slots[c] for c in chosen):
        wanted.setdefault(k, set()).add(i)
    picked = []
    for k, indices in sorted(wanted.items()):
        for i, (key, sample) in enumerate(
            checked_samples(root / shards[k]["file"], shards[k]["samples"])
        ):
            if i in indices:
                picked.append((key, sample))
    return picked


def _draw_skeleton(ax: Any, points: np.ndarray, shown: np.ndarray) -> None:
    """Lines between ``points (17, 2)`` where both ends are finite; filled dots where
    ``shown (17,)``, hollow elsewhere."""
    for a, b, colour in SKELETON_LINES:
        if np.all(np.isfinite(points[[a, b]])):
            ax.plot(*points[[a, b]].T, color=colour, lw=1.5)
    ax.scatter(*points[shown].T, s=12, c="k", zorder=3)
    ax.scatter(*points[~shown].T, s=12, facecolors="none", edgecolors="k", zorder=3)


def skeleton_pixels(sample: dict) -> np.ndarray:
    """``(Tc, C, 17, 2)`` the pixels the sheet draws: the exact projections
    (``fisheye_uv_projected``, the ground truth), not the detector's keypoints, which sit at
    (0, 0) where a joint was missed and would pull lines to the image corner."""
    return sample.get("fisheye_uv_projected", sample["fisheye_uv"])


def _image_entry(meta: dict, camera: str, n: int) -> str | None:
    """The entry name of camera ``camera``'s ``n``-th rendered image, if images were made."""
    images = meta["channels"].get("fisheye_images")
    if images is None:
        return None
    suffix = IMAGE_SUFFIX[images["format"]]
    return f"fisheye_image.{camera.replace('/', '-')}.{n:04d}{suffix}"


def _panel(ax: Any, key: str, sample: dict, rng: np.random.Generator) -> dict[str, Any]:
    from matplotlib.patches import Rectangle

    meta = sample["json"]
    title = f"{key} {meta.get('activity') or '-'} ({meta['split']})"
    if "fisheye_uv" in sample:
        # A frame with images where they were rendered (every image_stride-th).
        frames = sample.get("fisheye_image_frames", np.arange(sample["fisheye_uv"].shape[0]))
        n = int(rng.integers(len(frames)))
        frame = int(frames[n])
        seen = sample["fisheye_in_view"][frame]  # (C, 17)
        camera = int(np.argmax(seen.sum(axis=1)))
        model = meta["channels"]["fisheye"]["model"]
        name = meta["channels"]["fisheye"]["cameras"][camera]
        image = sample.get(_image_entry(meta, name, n))
        if image is not None:  # drawn at the keypoints' full-resolution pixel scale
            ax.imshow(image, extent=(0, model["width"], model["height"], 0))
        frame_box = Rectangle((0, 0), model["width"], model["height"], fill=False, ls="--")
        ax.add_patch(frame_box)
        _draw_skeleton(ax, skeleton_pixels(sample)[frame, camera], seen[camera])
        ax.set_xlim(-0.25 * model["width"], 1.25 * model["width"])
        ax.set_ylim(1.25 * model["height"], -0.25 * model["height"])  # image rows go down
        ax.set_title(f"{title}\n{name} frame {frame}", fontsize=7)
        return {"key": key, "split": meta["split"], "frame": frame, "view": name}
    frame = int(rng.integers(sample["body17"].shape[0]))
    joints = sample["body17"][frame]
    _draw_skeleton(ax, joints[:, [0, 2]], np.ones(len(joints), dtype=bool))
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title(f"{title}\nside view frame {frame}", fontsize=7)
    return {"key": key, "split": meta["split"], "frame": frame, "view": "side"}


def preview_sheet(
    root: Path, out: Path, samples: int = 12, seed: int = 0, split: str | None = None
) -> list[dict[str, Any]]:
    """Write the picture sheet of ``samples`` random samples of ``root`` to the PNG ``out``
    (atomically, never over a file avatarsim did not write:
    :func:`scripts.output_file.write_output`); return each panel's key, split, frame and view.

    Raises:
        DatasetError: as :func:`pick_samples`.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    picked = pick_samples(root, samples, seed, split)
    cols = min(4, len(picked))
    rows = -(-len(picked) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.0 * cols, 3.0 * rows), squeeze=False)
    rng = np.random.default_rng([seed, 1])
    panels = [_panel(ax, key, s, rng) for ax, (key, s) in zip(axes.flat, picked, strict=False)]
    for ax in axes.flat:
        ax.set_xticks([])
        ax.set_yticks([])
    for ax in axes.flat[len(picked) :]:
        ax.axis("off")
    fig.tight_layout()
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=100)
    plt.close(fig)
    write_output(out, buffer.getvalue(), "--out")
    return panels
