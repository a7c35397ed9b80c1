"""Atomic writes and the one JSON writer."""

from __future__ import annotations

import csv
import json
import math
import stat

import numpy as np
import pytest

from avatarsim.avatar_models.fileio import (
    atomic_file,
    file_mode,
    write_atomic,
    write_columns_csv,
    write_json,
)


def test_results_json_is_strict_json(tmp_path):
    path = write_json(
        tmp_path / "r.json", {"a": np.float64("nan"), "ok": np.bool_(True), "n": np.int64(3)}
    )
    data = json.loads(path.read_text(), parse_constant=lambda c: math.nan)  # would see NaN
    assert data == {"a": None, "ok": True, "n": 3}


def test_json_takes_arrays_tuples_and_other_objects(tmp_path):
    path = write_json(tmp_path / "sub" / "r.json", {"xs": np.arange(3), "t": (1, 2), "p": tmp_path})
    assert json.loads(path.read_text()) == {"xs": [0, 1, 2], "t": [1, 2], "p": str(tmp_path)}
    assert path.read_text().endswith("}\n")


def test_a_failed_write_leaves_the_old_file_and_no_temporary(tmp_path):
    path = write_atomic(tmp_path / "a.txt", "old")
    with pytest.raises(RuntimeError), atomic_file(path, "w") as fh:
        fh.write("half")
        raise RuntimeError("disk full")
    assert path.read_text() == "old" and [p.name for p in tmp_path.iterdir()] == ["a.txt"]
    assert stat.S_IMODE(path.stat().st_mode) == file_mode()


def test_columns_csv_reads_back_row_per_frame(tmp_path):
    columns = {"time_s": np.arange(3) / 90.0, "contact": np.array([True, False, True])}
    path = write_columns_csv(tmp_path / "f.csv", columns)
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["time_s", "contact"]
    np.testing.assert_array_equal(np.array(rows[1:], float), [[0, 1], [1 / 90, 0], [2 / 90, 1]])


def test_columns_of_unequal_length_write_nothing(tmp_path):
    with pytest.raises(ValueError):
        write_columns_csv(tmp_path / "f.csv", {"a": np.zeros(3), "b": np.zeros(2)})
    assert list(tmp_path.iterdir()) == []
