"""Masks compose layers without touching bones outside their sets."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models.generator import generate
from avatarsim.synthesis.base import SynthesisError
from avatarsim.synthesis.movebox.face import face_motion
from avatarsim.synthesis.movebox.masks import BONE_SETS, Layer, bone_set, compose


@pytest.fixture(scope="module")
def takes():
    return generate("box", duration_s=1.0, fps=30.0, seed=0), generate(
        "wave", duration_s=1.0, fps=30.0, seed=1
    )


def test_sets_partition_the_rig(takes):
    sk = takes[0].skeleton
    face, body = bone_set(sk, "face"), bone_set(sk, "body")
    upper, lower = bone_set(sk, "upper_body"), bone_set(sk, "lower_body")
    assert not (face & body).any() and (face | body).all()
    assert not (upper & lower).any() and ((upper | lower) == body).all()
    assert {sk.names[j] for j in np.flatnonzero(face)} == {
        "Bip01 Jaw", "Bip01 JawNub", "Bip01 L Eyelid", "Bip01 R Eyelid"
    }  # fmt: skip
    assert "Bip01 L Forearm" in {sk.names[j] for j in np.flatnonzero(upper)}
    assert "Bip01 L Calf" in {sk.names[j] for j in np.flatnonzero(lower)}


@pytest.mark.parametrize("name", BONE_SETS)
def test_a_layer_changes_only_its_bones(takes, name):
    base, other = takes
    out = compose(base, [Layer(other, name)])
    mask = bone_set(base.skeleton, name)
    assert np.allclose(out.local_rot[:, ~mask], base.local_rot[:, ~mask], atol=1e-15, rtol=0)
    assert np.allclose(out.local_rot[:, mask], other.local_rot[:, mask], atol=1e-15, rtol=0)


def test_body_from_one_take_lip_sync_on_top(takes):
    base, _ = takes
    jaw = np.linspace(0.0, 1.0, base.n_frames)
    face = face_motion(base.skeleton, base.fps, jaw, np.zeros(base.n_frames))
    out = compose(base, [Layer(face, "face")])
    body = bone_set(base.skeleton, "body")
    assert np.allclose(out.global_positions()[:, body], base.global_positions()[:, body])
    j = base.skeleton.index("Bip01 JawNub")
    assert not np.allclose(out.global_positions()[-1, j], base.global_positions()[-1, j])


def test_mismatched_layers_raise(takes):
    base, other = takes
    with pytest.raises(SynthesisError, match="fps"):
        compose(base, [Layer(other.resample(15.0), "face")])
    with pytest.raises(SynthesisError, match="unknown bone set"):
        compose(base, [Layer(other, "tail")])
