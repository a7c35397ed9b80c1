from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from avatarsim.avatar_models.body17 import INDEX
from avatarsim.avatar_models.generator import Subject, generate
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.scripts.dataset.channels import kinect_channel, physics_channel
from avatarsim.scripts.dataset.config import DeviceSetConfig, config_hash, from_dict
from avatarsim.scripts.dataset.plan import plan_samples
from avatarsim.scripts.dataset.sample import make_sample
from avatarsim.scripts.dataset.shards import read_samples, shard_bytes
from avatarsim.sim.humanoid import humanoid_for
from tests.scripts.dataset.builders import TINY

KINECT_V2 = DeviceSetConfig(name="k", kinect="kinect-v2")


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
    # four controller cameras at 30 Hz; a detector's keypoints: confidences in (0, 1] where
    # detected, 0 elsewhere, only joints in the image detected (occluded ones too, guessed;
    # a left/right swap may report a limb on the side not in the image), near but not at
    # the projections; in view: in the image and not occluded, some in-image joints hidden
    uv, conf, seen = arrays["fisheye_uv"], arrays["fisheye_conf"], arrays["fisheye_in_view"]
    found, exact = arrays["fisheye_detected"], arrays["fisheye_uv_projected"]
    assert uv.shape == exact.shape == (t, 4, 17, 2) and conf.shape == seen.shape == (t, 4, 17)
    middle = [INDEX[j] for j in ("head", "neck", "pelvis")]
    in_image = (np.abs(exact[..., 0] - 319.5) < 320) & (np.abs(exact[..., 1] - 239.5) < 240)
    in_image &= ~arrays["fisheye_lens_covered"][..., None]
    assert found.any() and not np.any(found[..., middle] & ~in_image[..., middle])
    assert not np.any(seen & ~in_image) and np.any(in_image & ~seen)
    assert np.all((conf[found] > 0) & (conf[found] <= 1)) and np.all(conf[~found] == 0)
    assert np.all(np.isfinite(uv)) and np.all(np.isfinite(exact[seen]))
    error = np.linalg.norm(uv - exact, axis=-1)[found]
    assert 0 < np.median(error) < 50  # pixels in a 640 x 480 image
    assert "projected" in meta["channels"]["fisheye"]["keypoints"]
    # Kinect V2: 25 joints, tracking states 0..2
    assert arrays["kinect_pos"].shape == (t, 25, 3)
    assert set(np.unique(arrays["kinect_state"])) <= {0, 1, 2}
    # physics labels per frame; a squat or wave keeps at least one foot down
    assert arrays["contact"].shape == (t, 2) and arrays["contact"].dtype == bool
    assert arrays["contact"].any(axis=1).mean() > 0.9
    assert arrays["penetration_m"].shape == (t,) and arrays["skate_m_s"].shape == (t, 2)
    assert sorted(arrays) == meta["arrays"]


@pytest.fixture(scope="module")
def wave():
    """1 s of a standing wave at the datasets' 30 Hz: both feet on the floor throughout."""
    return generate("wave", Subject(height_m=1.75), 1.0, 30.0, seed=4)


def _moved(motion, shift):
    return humanoid_for(motion.replace(root_pos=motion.root_pos + np.asarray(shift)))


def test_penetration_label_is_metres_of_depth_below_the_floor(wave):
    """Sinking the same pose 4 cm deeper deepens MuJoCo's deepest floor contact by 4 cm:
    the label's difference is 0.04 (metres), whatever the depth it starts from."""
    shallow, _ = physics_channel(_moved(wave, [0.0, 0.0, -0.03]))
    deep, meta = physics_channel(_moved(wave, [0.0, 0.0, -0.07]))
    assert shallow["penetration_m"].min() > 0.0  # in contact at every frame
    np.testing.assert_allclose(deep["penetration_m"] - shallow["penetration_m"], 0.04, atol=1e-4)
    assert meta["units"].startswith("m,")


def test_kinect_positions_follow_the_body_along_the_world_axes(wave):
    """The same body moved 0.8 m along +X and 0.3 m along -Y in the world (the sensor set up
    again in front of it, the same seed): its tracked joints move by exactly that, axis by
    axis, and sit on the ground truth's joints."""
    here, _ = kinect_channel(_moved(wave, [0.0, 0.0, 0.0]), KINECT_V2, seed=5)
    moved_humanoid = _moved(wave, [0.8, -0.3, 0.0])
    there, _ = kinect_channel(moved_humanoid, KINECT_V2, seed=5)
    tracked = (here["kinect_state"] == 2) & (there["kinect_state"] == 2)
    assert tracked.mean() > 0.5
    shift = (there["kinect_pos"] - here["kinect_pos"])[tracked]  # (n, 3)
    np.testing.assert_allclose(np.median(shift, axis=0), [0.8, -0.3, 0.0], atol=0.01)
    # The Kinect's head (joint 3 of the Kinect V2's 25) over the moved body's head: within
    # 5 cm along X and Y (the two joints are different points of the head, ~10 cm apart in Z).
    head = body17_positions(moved_humanoid.motion)[:, INDEX["head"], :2]
    gap = np.abs(there["kinect_pos"][:, 3, :2] - head)[there["kinect_state"][:, 3] == 2]
    assert np.all(np.median(gap, axis=0) < 0.05), np.median(gap, axis=0)


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


@pytest.fixture(scope="module")
def imaged_sample():
    """A short window (7 frames at 30 Hz) with fisheye JPEGs and Kinect depth every third
    frame, at a quarter of the image size."""
    devices = {
        "name": "img",
        "fisheye_images": "jpeg",
        "kinect": "kinect-v2",
        "kinect_depth": True,
        "image_scale": 0.25,
    }
    config = from_dict({**TINY, "window": {"seconds": 0.2, "fps": 30.0}, "devices": [devices]})
    spec = plan_samples(config)[0]
    return config, spec, *make_sample(config, spec, config_hash(config))


def test_images_and_depth_are_encoded_entries_at_the_stride(imaged_sample, tmp_path):
    config, spec, arrays, meta = imaged_sample
    frames = [0, 3, 6]  # every 3rd of the 7 camera (and Kinect) frames at 30 Hz
    assert arrays["fisheye_image_frames"].tolist() == frames
    assert arrays["kinect_depth_frames"].tolist() == frames
    cameras = meta["channels"]["fisheye_images"]["cameras"]
    jpegs = sorted(n for n in arrays if n.startswith("fisheye_image.") and n.endswith(".jpg"))
    assert len(cameras) == 4 and len(jpegs) == 4 * len(frames)
    assert all(arrays[n][:2] == b"\xff\xd8" for n in jpegs)  # JPEG start-of-image marker
    pngs = sorted(n for n in arrays if n.startswith("kinect_depth."))
    assert len(pngs) == len(frames) and arrays[pngs[0]][:8] == b"\x89PNG\r\n\x1a\n"
    # Decoded from a shard: RGB at a quarter of 640 x 480, depth 16-bit at the Kinect v2's
    # 512 x 424, with the performer's pixels about where the sensor record puts them.
    path = tmp_path / "s.tar"
    path.write_bytes(shard_bytes([(spec.key, arrays, meta)]))
    _, sample = next(read_samples(path))
    assert sample[jpegs[0]].shape == (120, 160, 3) and sample[jpegs[0]].dtype == np.uint8
    depth = sample[pngs[0]]
    assert depth.shape == (424, 512) and depth.dtype == np.uint16
    performer_mm = 1000 * meta["channels"]["kinect"]["performer_depth_m_median"]
    assert np.any(np.abs(depth.astype(float) - performer_mm) < 300)


def test_images_are_deterministic_and_leave_the_other_channels_unchanged(imaged_sample):
    config, spec, arrays, _ = imaged_sample
    again, _ = make_sample(config, spec, config_hash(config))
    assert all(_same(arrays[n], again[n]) for n in arrays)
    plain = replace(config.devices[0], fisheye_images="none", kinect_depth=False)
    without, _ = make_sample(replace(config, devices=(plain,)), spec, config_hash(config))
    assert set(without) < set(arrays)
    assert all(_same(without[n], arrays[n]) for n in without)


def _same(a, b) -> bool:
    return a == b if isinstance(a, bytes) else np.array_equal(a, b)


def test_body17_angles_label_reproduces_the_keypoints(first_sample):
    """The 43-DoF label channel (ControllerPose §4.3) gives back the body17 keypoints by FK
    (float32 storage: within 1 mm)."""
    from avatarsim.avatar_models.body17_angles import angles_from_positions, positions_from_angles

    _, arrays, _ = first_sample
    body17 = arrays["body17"].astype(np.float64)
    assert arrays["body17_angles"].shape == (len(body17), 43)
    _, lengths = angles_from_positions(body17)
    back = positions_from_angles(arrays["body17_angles"].astype(np.float64), lengths)
    assert np.abs(back - (body17 - body17[:, INDEX["pelvis"] : INDEX["pelvis"] + 1])).max() < 1e-3


def test_composite_and_torso_views_are_detections_inside_their_images(first_sample):
    """ControllerPose's four 2D poses (§4.3): each controller's composite and torso-normal
    view, reported by the detector: confidences in (0, 1] exactly where detected, pixels
    inside the view, and a body that both views see (a waving or squatting user in front
    of the controllers)."""
    _, arrays, meta = first_sample
    fisheye = meta["channels"]["fisheye"]
    assert fisheye["views"] == [
        f"{side}_controller/{kind}" for side in ("left", "right") for kind in ("composite", "torso")
    ]
    uv, conf = arrays["fisheye_view_uv"], arrays["fisheye_view_conf"]
    found = arrays["fisheye_view_detected"]
    assert uv.shape == (meta["frames"], 4, 17, 2) and found.dtype == bool
    assert np.all((conf[found] > 0) & (conf[found] <= 1)) and np.all(conf[~found] == 0)
    assert np.all(uv[~found] == 0)
    torso = [INDEX[j] for j in ("l_shoulder", "r_shoulder", "l_hip", "r_hip")]
    for v, name in enumerate(fisheye["views"]):
        width, height = fisheye["view_sizes"][name.split("/")[0]]
        seen = found[:, v]
        inside = (uv[:, v, :, 0] > -0.5) & (uv[:, v, :, 0] < width - 0.5)
        inside &= (uv[:, v, :, 1] > -0.5) & (uv[:, v, :, 1] < height - 0.5)
        # The detector's noise may push a joint at the edge a little outside.
        assert inside[seen].mean() > 0.95, name
        if name.endswith("/composite"):
            assert seen.any(axis=1).mean() > 0.5, name  # the user is in front of the hands
            # A torso view exists only where the composite reported all four torso corners.
            corners = seen[:, torso].all(axis=1)
            assert not np.any(found[:, v + 1].any(axis=1) & ~corners), name
