"""The report of a control run: per-frame columns with the fall marked, and its three files."""

from __future__ import annotations

import json

import numpy as np

from avatarsim.avatar_models.body17 import BODY17
from avatarsim.sim.control.controller import ControlResult
from avatarsim.sim.control.report import per_frame, write_outputs


def _result(frames: int = 10, fall_frame: int | None = 6) -> ControlResult:
    error = np.full((frames, 17), 0.02)  # 2 cm everywhere
    return ControlResult(
        qpos=np.tile([0.0, 0.0, 0.9, 1.0, 0.0, 0.0, 0.0], (frames, 1)),
        body17_error=error,
        torque=np.full((frames, 3), -2.0),
        power=np.arange(frames, dtype=float),
        fall_frame=fall_frame,
        fps=10.0,
        reference_frame=np.arange(frames, dtype=float),
    )


def test_per_frame_columns_mark_the_fall():
    columns = per_frame(_result())
    np.testing.assert_allclose(columns["time_s"], np.arange(10) / 10.0)
    np.testing.assert_allclose(columns["body17_err_cm"], 2.0)
    assert {f"err_{name}_cm" for name in BODY17} <= set(columns)
    np.testing.assert_array_equal(columns["fallen"], [0] * 6 + [1] * 4)
    np.testing.assert_allclose(columns["mean_abs_torque_nm"], 2.0)
    np.testing.assert_allclose(columns["root_height_m"], 0.9)


def test_outputs_are_csv_json_and_plot(tmp_path):
    summary = {"mode": "plain", "fell": True}
    written = write_outputs(_result(), summary, tmp_path, "a run")
    assert {p.name for p in written.values()} == {"control.csv", "control.json", "control.png"}
    assert json.loads((tmp_path / "control.json").read_text()) == summary
    rows = np.genfromtxt(tmp_path / "control.csv", delimiter=",", names=True)
    assert len(rows) == 10 and rows["fallen"].sum() == 4
    assert (tmp_path / "control.png").stat().st_size > 1000
