"""Fuzz: mutated ASF/AMC pairs either load or raise MotionFormatError, nothing else."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from avatarsim.avatar_models.errors import MotionFormatError
from avatarsim.avatar_models.formats.asf_amc import read_asf_amc
from avatarsim.avatar_models.motion import Motion

DATA = Path(__file__).resolve().parents[1] / "data" / "asf_amc"
BODY_AMC = "\n".join(
    [":FULLY-SPECIFIED", ":DEGREES", "1", "root 1 2 3 4 5 6", "lfemur 10 20 30", "ltibia 40"]
    + ["lfoot 5 -5", "lclavicle 3 4", "2", "root 0 0 0 0 0 0", "head 1 2 3", "lradius 9"]
)
BASES = [
    ((DATA / "chain.asf").read_text(), (DATA / "chain.amc").read_text()),
    ((DATA / "body.asf").read_text(), BODY_AMC),
]
# Tokens that hit the parser's decisions: numbers it must reject, keywords out of place.
NASTY = ["nan", "inf", "-inf", "1e400", "abc", "", "(", ")", ",", "1_0", "²", "-", "0", "-1"]
NASTY += ["7", "99999999999", ":units", ":root", ":bonedata", ":hierarchy", ":DEGREES", "begin"]
NASTY += ["end", "root", "a", "b", "lfemur", "XYZ", "XXY", "rx", "tx", "dof", "limits", "#"]
token = st.one_of(st.sampled_from(NASTY), st.text(max_size=6))
mutation = st.tuples(
    st.sampled_from(["asf", "amc"]),
    st.sampled_from(["delete", "duplicate", "swap", "token", "insert", "truncate"]),
    st.integers(0, 10_000),
    st.integers(0, 10_000),
    token,
)


def _mutate(text: str, kind: str, i: int, j: int, tok: str) -> str:
    lines = text.split("\n")
    a, b = i % len(lines), j % len(lines)
    if kind == "delete":
        del lines[a]
    elif kind == "duplicate":
        lines.insert(a, lines[b])
    elif kind == "swap":
        lines[a], lines[b] = lines[b], lines[a]
    elif kind == "insert":
        lines.insert(a, tok)
    elif kind == "truncate":
        return text[: i % (len(text) + 1)]
    else:  # replace one whitespace-separated token of line a
        words = lines[a].split(" ")
        words[j % len(words)] = tok
        lines[a] = " ".join(words)
    return "\n".join(lines)


@pytest.fixture(scope="module")
def workdir(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("asf_amc_fuzz")


@settings(max_examples=4000, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(base=st.integers(0, len(BASES) - 1), mutations=st.lists(mutation, min_size=1, max_size=3))
def test_only_motion_format_errors_escape(workdir, base, mutations):
    texts = dict(zip(("asf", "amc"), BASES[base], strict=True))
    for target, kind, i, j, tok in mutations:
        texts[target] = _mutate(texts[target], kind, i, j, tok)
    asf, amc = workdir / "s.asf", workdir / "s.amc"
    asf.write_text(texts["asf"], encoding="utf-8", errors="surrogatepass")
    amc.write_text(texts["amc"], encoding="utf-8", errors="surrogatepass")
    try:
        motion = read_asf_amc(amc, asf=asf)
    except MotionFormatError as exc:
        assert exc.path in (str(asf), str(amc))
        return
    assert isinstance(motion, Motion)
    assert np.all(np.isfinite(motion.global_positions()))
