"""Recordings: pieces chain in order without copying, branches share their beginning."""

from __future__ import annotations

import numpy as np

from avatarsim.sim.control.records import FrameRecord, Recording


def _record(frame: float) -> FrameRecord:
    return FrameRecord(frame, np.full(3, frame), np.zeros((17, 3)), np.ones(2), 2.0 * frame, False)


def test_pieces_chain_in_order_and_branches_share_the_start():
    start = Recording().then([_record(0.0)])
    left = start.then([_record(1.0), _record(2.0)]).then([]).then([_record(3.0)])
    right = start.then([_record(1.5)])
    assert [r.reference_frame for r in left.records()] == [0.0, 1.0, 2.0, 3.0]
    assert [r.reference_frame for r in right.records()] == [0.0, 1.5]
    assert left.records()[0] is right.records()[0]  # the shared start, not a copy
    columns = left.columns()
    assert columns["qpos"].shape == (4, 3) and columns["sites"].shape == (4, 17, 3)
    np.testing.assert_array_equal(columns["power"], [0.0, 2.0, 4.0, 6.0])
    assert columns["unstable"].dtype == bool
