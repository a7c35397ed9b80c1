from __future__ import annotations

import numpy as np
import pytest

from avatar_models.body17 import INDEX
from scripts.dataset.config import config_hash, from_dict
from scripts.dataset.plan import plan_samples
from scripts.dataset.sample import make_sample
from tests.scripts.dataset.builders import TINY


@pytest.fixture(scope="module")
def first_sample():
    config = from_dict(TINY)
    spec = plan_samples(config)[0]
    return spec, *make_sample(config, spec, config_hash(config))


def test_ground_truth_and_devices_agree(first_sample):
    spec, arrays, meta = first_sample
    t = meta["frames"]
    assert t == 31  # 1 s at 30 Hz, both ends
    assert arrays["body17"].shape == (t, 17, 3) and arrays["body17"].dtype == np.float32
    assert arrays["qpos"].shape[0] == t
    head = arrays["body17"][:, INDEX["head"]]
    assert 1.3 < np.median(head[:, 2]) < 2.1  # a standing adult's head, Z up
    # VR at 90 Hz over the same second; the headset sits on the head (within a head's size)
    assert arrays["vr_pos"].shape == (91, 3, 3) and arrays["vr_valid"].shape == (91, 3)
    hmd = meta["channels"]["vr"]["devices"].index("hmd")
    gap = np.linalg.norm(arrays["vr_pos"][::3, hmd] - head, axis=-1)
    assert np.median(gap) < 0.2
    # four controller cameras at 30 Hz, keypoints with confidences in (0, 1]
    uv, conf, seen = arrays["fisheye_uv"], arrays["fisheye_conf"], arrays["fisheye_in_view"]
    assert uv.shape == (t, 4, 17, 2) and conf.shape == seen.shape == (t, 4, 17)
    assert seen.any() and np.all((conf > 0) & (conf <= 1))
    assert np.all(np.isfinite(uv[seen]))
    assert "projected" in meta["channels"]["fisheye"]["keypoints"]
    # Kinect V2: 25 joints, tracking states 0..2
    assert arrays["kinect_pos"].shape == (t, 25, 3)
    assert set(np.unique(arrays["kinect_state"])) <= {0, 1, 2}
    # physics labels per frame; a squat or wave keeps at least one foot down
    assert arrays["contact"].shape == (t, 2) and arrays["contact"].dtype == bool
    assert arrays["contact"].any(axis=1).mean() > 0.9
    assert arrays["penetration_m"].shape == (t,) and arrays["skate_m_s"].shape == (t, 2)
    assert sorted(arrays) == meta["arrays"]


def test_provenance(first_sample):
    spec, _, meta = first_sample
    assert meta["split"] == spec.split and meta["group"] == spec.window.group
    assert 1.5 <= meta["subject"]["height_m"] <= 1.95
    prov = meta["provenance"]
    assert prov["seeds"]["devices"] == spec.seed and prov["seeds"]["window"] == spec.window.seed
    assert prov["config_hash"] == config_hash(from_dict(TINY))
    assert prov["package_version"]


@pytest.mark.mocap
def test_real_clip_sample(mocap_dir):
    config = from_dict(
        {
            **TINY,
            "sources": [
                {"kind": "mocap", "path": str(mocap_dir / "cmu"), "activities": ["running"]}
            ],
        }
    )
    spec = plan_samples(config)[0]
    arrays, meta = make_sample(config, spec, config_hash(config))
    assert meta["provenance"]["clip"].endswith(".bvh") and meta["group"].startswith("clip:")
    assert meta["activity"] == "running"
    assert arrays["body17"].shape == (31, 17, 3)
    assert 1.3 < np.median(arrays["body17"][:, INDEX["head"], 2]) < 2.1


def test_body17_angles_label_reproduces_the_keypoints(first_sample):
    """The 43-DoF label channel (ControllerPose §4.3) gives back the body17 keypoints by FK
    (float32 storage: within 1 mm)."""
    from avatar_models.body17_angles import angles_from_positions, positions_from_angles

    _, arrays, _ = first_sample
    body17 = arrays["body17"].astype(np.float64)
    assert arrays["body17_angles"].shape == (len(body17), 43)
    _, lengths = angles_from_positions(body17)
    back = positions_from_angles(arrays["body17_angles"].astype(np.float64), lengths)
    assert np.abs(back - (body17 - body17[:, INDEX["pelvis"] : INDEX["pelvis"] + 1])).max() < 1e-3
