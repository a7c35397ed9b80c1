"""Fuzz: mutated BVH files either load or raise MotionFormatError, never anything else."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from avatarsim.avatar_models.errors import MotionFormatError
from avatarsim.avatar_models.formats.bvh import read_bvh, write_bvh
from avatarsim.avatar_models.motion import Motion
from tests.avatar_models.test_bvh import BANDAI_LIKE, TWO_JOINT, random_motion


def _valid_files() -> list[bytes]:
    files = [TWO_JOINT.encode(), BANDAI_LIKE.encode()]
    with tempfile.TemporaryDirectory() as tmp:
        for seed in range(4):
            rng = np.random.default_rng(seed)
            path = write_bvh(random_motion(rng, n_joints=4 + seed, n_frames=3), Path(tmp) / "v.bvh")
            files.append(path.read_bytes())
    return files


VALID = _valid_files()
TOKENS = st.sampled_from(
    [
        "{",
        "}",
        "ROOT",
        "JOINT",
        "End",
        "Site",
        "OFFSET",
        "CHANNELS",
        "MOTION",
        "Frames:",
        "Frame",
        "Time:",
        "Xposition",
        "Zrotation",
        "6",
        "3",
        "0",
        "-1",
        "nan",
        "inf",
        "-inf",
        "1e999",
        "1e308",
        "-1e308",
        "1e-320",
        "9" * 40,
        "0x1F",
        "1_0",
        "",
        "\n",
        "\t",
        "\r",
        "\x00",
        "é",
        "\u2028",
        "\x1c",
    ]
)


@st.composite
def mutated(draw) -> bytes:
    data = draw(st.sampled_from(VALID))
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(
            st.sampled_from(["truncate", "delete", "duplicate", "replace", "insert", "bytes"])
        )
        words = data.split(b" ")
        k = draw(st.integers(0, max(0, len(words) - 1)))
        if kind == "truncate":
            data = data[: draw(st.integers(0, len(data)))]
        elif kind == "delete":
            data = b" ".join(words[:k] + words[k + 1 :])
        elif kind == "duplicate":
            data = b" ".join(words[: k + 1] + words[k:])
        elif kind in ("replace", "insert"):
            token = draw(TOKENS).encode()
            data = b" ".join(words[:k] + [token] + words[k + (kind == "replace") :])
        else:
            at = draw(st.integers(0, len(data)))
            data = data[:at] + draw(st.binary(min_size=1, max_size=8)) + data[at:]
    return data


@pytest.fixture(scope="module")
def scratch():
    with tempfile.TemporaryDirectory() as tmp:
        yield Path(tmp) / "fuzz.bvh"


@settings(max_examples=5000, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=mutated(), unit=st.sampled_from(["cm", None]))
def test_mutated_files_raise_only_format_errors(scratch, data, unit):
    scratch.write_bytes(data)
    try:
        motion = read_bvh(scratch, unit=unit)
    except MotionFormatError as exc:
        assert exc.path == str(scratch)
        return
    assert isinstance(motion, Motion)
    assert np.all(np.isfinite(motion.root_pos)) and np.all(np.isfinite(motion.local_rot))
