"""``avatarsim eval leaderboard``: every registered method on the same test motions, one
table with accuracy, physics and latency, written as JSON, a plot and a page."""

from __future__ import annotations

import json

import numpy as np
from typer.testing import CliRunner

from scripts.cli import app
from scripts.leaderboard import COLUMNS
from synthesis.methods import ready_methods

runner = CliRunner()


def test_leaderboard_on_a_small_builtin_set(tmp_path):
    out, js = tmp_path / "out", tmp_path / "board.json"
    result = runner.invoke(
        app,
        ["eval", "leaderboard", "--library", "builtin", "--classes", "box", "--subjects", "2",
         "--takes", "1", "--duration", "1.5", "--out", str(out), "--json", str(js)],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    board = json.loads(js.read_text())
    assert set(board["methods"]) == set(ready_methods())
    assert board["trials"] == 2  # both subjects, each held out once
    for name, row in board["methods"].items():
        assert set(row) == set(COLUMNS), name
        assert all(np.isfinite(v) for v in row.values()), name
        assert row["step_ms_p99"] >= row["step_ms_p50"] > 0
    # The IK steers the wrists to the controllers; the paper's CoolMoves does not, and arm
    # IK on top of it is what brings its hands there.
    hands = {name: row["hands_cm"] for name, row in board["methods"].items()}
    assert hands["ik"] < 1.0 and hands["coolmoves+arm-ik"] < hands["coolmoves"]
    assert {"leaderboard.json", "leaderboard.png", "leaderboard.html"} <= {
        p.name for p in out.iterdir()
    }
    page = (out / "leaderboard.html").read_text()
    assert "coolmoves+arm-ik" in page and "data:image/png;base64" in page
