"""The method registry: ``coolmoves`` is the paper's pipeline (no arm IK, no foot pinning),
arm IK is a method of its own, and every name builds a synthesiser reporting that name."""

from __future__ import annotations

import pytest

from avatarsim.render_cams import VRSetup
from avatarsim.synthesis.base import SynthesisError
from avatarsim.synthesis.methods import METHODS, MethodInputs, build
from avatarsim.synthesis.scoring import hand_correlation
from tests.synthesis.conftest import TEST_SUBJECT


def test_coolmoves_is_the_papers_pipeline():
    paper = METHODS["coolmoves"].options
    # §3.1: hands come from the blended database poses; the paper has no IK on the arms and
    # no foot pinning, and it aligns and smooths (its ablation's last step).
    assert paper.arm_ik == 0.0 and not paper.foot_contact
    assert paper.align and paper.smooth and paper.clamp and paper.matcher == "knn"
    assert METHODS["coolmoves+arm-ik"].options.arm_ik > 0
    assert {"coolmoves", "coolmoves+arm-ik", "coolmoves-gmm", "ik"} <= set(METHODS)


def test_every_method_builds_under_its_name(small_db, test_motion):
    inputs = MethodInputs(lambda: small_db, TEST_SUBJECT.height_m, small_db.skeleton)
    stream = VRSetup().sample(test_motion[:60], seed=0)
    for name in ("coolmoves", "coolmoves+arm-ik"):
        synth = build(name, inputs)
        assert synth.name == name
        assert synth.run(stream).n_frames == stream.n_samples
    with pytest.raises(SynthesisError, match="available"):
        build("magic", inputs)


def test_arm_ik_is_what_brings_the_hands_to_the_controllers(small_db, test_motion):
    """The two differ by the arm IK only: it is what raises the hand correlation, so a hand
    number reported for ``coolmoves`` is the paper's method's own."""
    inputs = MethodInputs(lambda: small_db, TEST_SUBJECT.height_m, small_db.skeleton)
    stream = VRSetup().sample(test_motion, seed=0)
    paper = hand_correlation(build("coolmoves", inputs).run(stream), stream)
    arm_ik = hand_correlation(build("coolmoves+arm-ik", inputs).run(stream), stream)
    assert min(arm_ik.values()) > min(paper.values())
    assert min(arm_ik.values()) > 0.99
