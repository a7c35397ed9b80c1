"""Atomic writes and the one JSON writer."""

from __future__ import annotations

import json
import math
import stat

import numpy as np
import pytest

from avatar_models.fileio import atomic_file, file_mode, write_atomic, write_json


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
