from __future__ import annotations

import json

import numpy as np
from matplotlib.colors import to_rgb
from PIL import Image
from typer.testing import CliRunner

from avatarsim.scripts.cli import app
from avatarsim.scripts.dataset.config import load_config
from avatarsim.scripts.dataset.manifest import read_manifest
from avatarsim.scripts.dataset.preview import (
    SIDE_COLOURS,
    SKELETON_LINES,
    preview_sheet,
    skeleton_pixels,
)
from avatarsim.scripts.dataset.runner import generate
from avatarsim.scripts.dataset.shards import read_samples
from tests.scripts.dataset.builders import write_config

runner = CliRunner()


def test_skeleton_lines_connect_all_17_joints_as_a_tree():
    joints = {j for a, b, _ in SKELETON_LINES for j in (a, b)}
    assert joints == set(range(17)) and len(SKELETON_LINES) == 16  # a tree on 17 nodes


def test_preview_draws_random_samples_of_the_dataset(tiny_dataset, tmp_path):
    panels = preview_sheet(tiny_dataset, tmp_path / "a.png", samples=4, seed=1)
    keys = [p["key"] for p in panels]
    manifest = read_manifest(tiny_dataset)
    assert len(set(keys)) == 4 and manifest["samples"] == 10
    assert all(p["view"].startswith(("left", "right")) for p in panels), panels  # a camera
    image = np.asarray(Image.open(tmp_path / "a.png").convert("L"))
    assert image.shape == (300, 1200)  # 1 row x 4 columns of 3 in at 100 dpi
    assert (image < 128).mean() > 0.002  # lines and dots, not an empty sheet
    # Each panel draws both sides' limbs in their own colours (left blue, right red): a
    # sheet with frames and titles but no skeleton, or one side lost, fails here.
    rgb = np.asarray(Image.open(tmp_path / "a.png").convert("RGB")).astype(float)
    for colour in SIDE_COLOURS.values():
        near = np.linalg.norm(rgb - 255 * np.array(to_rgb(colour)), axis=-1) < 40
        per_panel = near.reshape(300, 4, 300).sum(axis=(0, 2))
        assert per_panel.min() > 5, (colour, per_panel)  # min 17 over 10 seeds x 4 panels
    other = preview_sheet(tiny_dataset, tmp_path / "c.png", samples=4, seed=2)
    assert [p["key"] for p in other] != keys  # another seed, other samples


def test_preview_cli_writes_the_sheet_and_rejects_bad_input(tiny_dataset, tmp_path):
    out, report = tmp_path / "sheet.png", tmp_path / "p.json"
    args = ["dataset", "preview", str(tiny_dataset), "--out", str(out), "--samples", "3"]
    result = runner.invoke(app, [*args, "--split", "train", "--json", str(report)])
    assert result.exit_code == 0, result.output
    panels = json.loads(report.read_text())["panels"]
    assert out.is_file() and len(panels) == 3 and {p["split"] for p in panels} == {"train"}
    assert runner.invoke(app, [*args[:-1], "0"]).exit_code == 2
    assert runner.invoke(app, [*args, "--split", "dev"]).exit_code == 2
    empty = tmp_path / "empty"
    empty.mkdir()
    assert runner.invoke(app, ["dataset", "preview", str(empty)]).exit_code == 2


def test_preview_draws_the_rendered_image_under_the_skeleton(tmp_path):
    devices = [{"name": "img", "fisheye_images": "png", "image_scale": 0.25}]
    changes = {"window": {"seconds": 0.2, "fps": 30.0}, "devices": devices}
    sources = [{"kind": "builtin", "activities": ["wave"], "subjects": 3}]
    config = load_config(write_config(tmp_path / "c.toml", sources=sources, **changes))
    generate(config, tmp_path / "ds")
    panels = preview_sheet(tmp_path / "ds", tmp_path / "a.png", samples=3, seed=0)
    assert all(p["frame"] % 3 == 0 for p in panels)  # frames with images (every 3rd)
    image = np.asarray(Image.open(tmp_path / "a.png").convert("L"))
    # The images fill their frames: 34 % of the sheet is not white here, 7 % of a
    # keypoints-only sheet of 8 panels (frame boxes, skeletons and titles).
    assert (image < 250).mean() > 0.2


def test_preview_draws_the_exact_projections_not_missed_detections(tiny_dataset):
    # Regression: missed detections sit at (0, 0) in fisheye_uv; drawn, every panel had lines
    # from its image corner. The sheet draws the ground truth's projections instead.
    shard = sorted(tiny_dataset.rglob("*.tar"))[0]
    samples = [sample for _, sample in read_samples(shard)]
    missed = [s for s in samples if (s["fisheye_in_view"] & ~s["fisheye_detected"]).any()]
    assert missed, "the detector misses some in-view joints of the tiny dataset"
    for sample in missed:
        drawn = skeleton_pixels(sample)[sample["fisheye_in_view"]]
        assert np.all(np.abs(drawn).sum(-1) > 0)  # no in-view joint at the corner
        np.testing.assert_array_equal(
            drawn, sample["fisheye_uv_projected"][sample["fisheye_in_view"]]
        )
