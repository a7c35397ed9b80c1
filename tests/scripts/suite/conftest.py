"""Tiny scenarios for the suite tests: a 1 s built-in walk with only the stages a test needs
(pictures: one frame, no GIF), so a suite of three runs in seconds."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from avatarsim.scripts.cli import app


def write_scenario(
    folder: Path, name: str, top: str = "", motion: str = "", tables: str = "", file: str = ""
) -> Path:
    """``folder/<file or name>.toml``: a 1 s walk named ``name``, with ``top`` (top-level
    keys), ``motion`` (lines of [motion]) and ``tables`` (more tables) added."""
    folder.mkdir(parents=True, exist_ok=True)
    text = f"""name = "{name}"
seed = 1
{top}
[motion]
activity = "walk"
duration_s = 1.0
{motion}
[report]
picture_frames = 1
gif = false
{tables}
"""
    path = folder / f"{file or name}.toml"
    path.write_text(text, encoding="utf-8")
    return path


def invoke(*args: str | Path):
    return CliRunner().invoke(app, ["run", *map(str, args)])


@pytest.fixture(scope="session")
def three_scenarios(tmp_path_factory) -> Path:
    """One passing, one failing a threshold (a 1 s clip has more than 10 frames) and one
    whose sunk feet must fail the penetration check (expected to fail)."""
    folder = tmp_path_factory.mktemp("three")
    write_scenario(folder, "pass", tables="[thresholds]\nreplay_error_mm_max = 1.0")
    write_scenario(folder, "fail", tables="[thresholds]\nframes = 10")
    write_scenario(
        folder, "sunk", top='expect_fail = ["penetration_cm_p95"]', motion='corrupt = "sink_feet"'
    )
    return folder


@pytest.fixture(scope="session")
def three_suite(three_scenarios, tmp_path_factory) -> tuple[Path, int]:
    """The three scenarios run as a suite with 2 workers: (output folder, exit code)."""
    out = tmp_path_factory.mktemp("three-out") / "suite"
    result = invoke(three_scenarios, "--out", out, "--workers", "2")
    assert result.exit_code in (0, 1), result.output
    return out, result.exit_code
