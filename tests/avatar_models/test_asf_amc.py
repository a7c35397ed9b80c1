"""ASF/AMC reader: hand-computed poses, an amc_parser-style reference, units, limits, errors."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from avatarsim.avatar_models.errors import MotionFormatError
from avatarsim.avatar_models.formats import load_motion, save_motion
from avatarsim.avatar_models.formats.asf_amc import bone_tip_positions, read_asf, read_asf_amc

DATA = Path(__file__).resolve().parents[1] / "data" / "asf_amc"
CHAIN_ASF = DATA / "chain.asf"
BODY_ASF = DATA / "body.asf"
INCH = 0.0254


def _rx(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def _ry(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def _rz(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def _euler_xyz(deg):
    """amc_parser's ``euler2mat(x, y, z)`` ('sxyz'): Rz Ry Rx."""
    ax, ay, az = np.radians(deg)
    return _rz(az) @ _ry(ay) @ _rx(ax)


def _to_z_up(v):
    """Y-up facing +Z -> Z-up facing +X: (x, y, z) -> (z, x, y)."""
    v = np.asarray(v, dtype=float)
    return v[..., [2, 0, 1]]


def test_chain_known_positions():
    """Positions worked out by hand (module docstring conventions), in inches, Y up."""
    m = load_motion(DATA / "chain.amc", asf=CHAIN_ASF)
    assert m.skeleton.names == ("root", "a", "b", "b_end")
    assert m.n_frames == 3 and m.fps == 120.0
    pos = m.global_positions() / INCH
    # Frame 1, rest: a starts at the root, b at a's tip (2,0,0), b_end at (2,3,0).
    expected_rest = _to_z_up([[0, 0, 0], [0, 0, 0], [2, 0, 0], [2, 3, 0]])
    np.testing.assert_allclose(pos[0], expected_rest, atol=1e-9)
    # Frame 2: root at (1,2,3); a rx=90 about its axis frame C=Rz(90), i.e. about world +Y:
    # a's tip (1,0,0)*2 -> (0,0,-2). b: rz=90 maps (0,3,0) -> (-3,0,0), then a's turn -> (0,0,3).
    p = np.array([1.0, 2.0, 3.0])
    expected = _to_z_up([p, p, p + [0, 0, -2], p + [0, 0, 1]])
    np.testing.assert_allclose(pos[1], expected, atol=1e-9)
    # Frame 3: root rx=90 then ry=90 (x applied first): (2,0,0) -> (0,0,-2); (2,3,0) -> (3,0,-2).
    expected = _to_z_up([[0, 0, 0], [0, 0, 0], [0, 0, -2], [3, 0, -2]])
    np.testing.assert_allclose(pos[2], expected, atol=1e-9)


def test_chain_limits_and_meta():
    m = read_asf_amc(DATA / "chain.amc", asf=CHAIN_ASF, fps=60)
    assert m.fps == 60.0
    assert m.skeleton.limits["a"]["rx"] == pytest.approx((np.radians(-45), np.radians(90)))
    lo, hi = m.skeleton.limits["b"]["rz"]
    assert lo == -np.inf and hi == np.inf
    assert set(m.skeleton.limits) == {"a", "b"}
    assert m.meta["asf"] == str(CHAIN_ASF) and m.meta["first_frame"] == 1
    assert m.meta["metres_per_unit"] == pytest.approx(INCH)
    # a's limit axes: C = Rz(90) in Y-up, i.e. its x axis is world +Y (Z-up: +Z).
    np.testing.assert_allclose(np.array(m.meta["limit_axes"]["a"])[:, 0], [0, 0, 1], atol=1e-12)


def test_cmu_units_and_rest_pose():
    """CMU ``length 0.45``: 1 unit = 0.0254/0.45 m = 0.056444 m; rest pose faces +X, left +Y."""
    asf = read_asf(BODY_ASF)
    assert asf.metres_per_unit == pytest.approx(0.056444, abs=1e-6)
    assert asf.name == "SYNTH" and asf.version == "1.10" and asf.units["angle"] == "deg"
    assert "CMU-like" in asf.documentation
    # read_asf's axis frame is amc_parser's euler2mat('sxyz') of the axis angles.
    np.testing.assert_allclose(asf.bones["lfoot"].axis, _euler_xyz([-90, 7, 20]), atol=1e-12)
    amc = "1\nroot 0 0 0 0 0 0\n"
    path = DATA.parent / "unused.amc"
    m = _motion_from_text(path, amc, BODY_ASF)
    sk = m.skeleton
    lfemur = sk.offsets[sk.index("lfemur")]  # = lhipjoint's vector
    np.testing.assert_allclose(lfemur, _to_z_up([0.7, -0.65, 0.3]) * 2.4 * 0.0254 / 0.45)
    rest = m.global_positions()[0]
    assert rest[sk.index("lfemur"), 1] > 0  # left hip on +Y
    assert rest[sk.index("lfoot_end"), 0] > rest[sk.index("lfoot"), 0]  # toes point +X
    assert rest[sk.index("head_end"), 2] > rest[sk.index("head"), 2]  # head up +Z
    m2 = _motion_from_text(path, amc, BODY_ASF, unit=1.0)
    np.testing.assert_allclose(m2.skeleton.offsets * 0.0254 / 0.45, sk.offsets)


def _motion_from_text(path_hint: Path, amc_text: str, asf: Path, **options):
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        amc = Path(tmp) / path_hint.name
        amc.write_text(amc_text)
        return read_asf_amc(amc, asf=asf, **options)


def _reference_tips(asf, root_values, bone_values):
    """amc_parser-style FK: bone tips in the ASF's Y-up frame and file units (one frame)."""
    glob = {"root": _euler_xyz(root_values[3:])}
    tip = {"root": np.asarray(root_values[:3], dtype=float)}
    for name, bone in asf.bones.items():
        angles = np.zeros(3)
        for dof, v in zip(bone.dofs, bone_values.get(name, []), strict=True):
            angles["xyz".index(dof[1])] = v
        parent = asf.parent[name]
        glob[name] = glob[parent] @ bone.axis @ _euler_xyz(angles) @ bone.axis.T
        tip[name] = tip[parent] + bone.length * glob[name] @ bone.direction
    return tip


def test_body_matches_reference_reader(tmp_path):
    """Random poses on a CMU-like skeleton: bone tips equal an amc_parser-style FK."""
    rng = np.random.default_rng(7)
    asf = read_asf(BODY_ASF)
    frames, lines = [], []
    for f in range(1, 6):
        root = np.concatenate([rng.uniform(-20, 20, 3), rng.uniform(-90, 90, 3)])
        bones = {n: rng.uniform(-60, 60, len(b.dofs)) for n, b in asf.bones.items() if b.dofs}
        # Frame 3 leaves out thorax: a missing bone reads as zero.
        written = {n: v for n, v in bones.items() if not (f == 3 and n == "thorax")}
        bones["thorax"] = bones["thorax"] if f != 3 else np.zeros(3)
        lines.append(f"{f}\nroot {' '.join(map(str, root))}")
        lines += [f"{n} {' '.join(map(str, v))}" for n, v in written.items()]
        frames.append((root, bones))
    amc = tmp_path / "body.amc"
    amc.write_text(":FULLY-SPECIFIED\n:DEGREES\n" + "\n".join(lines) + "\n")
    m = read_asf_amc(amc, asf=BODY_ASF)
    tips = bone_tip_positions(m)
    scale = 0.0254 / 0.45
    for t, (root, bones) in enumerate(frames):
        ref = _reference_tips(asf, root, bones)
        for name, p in ref.items():
            got = tips[t, m.skeleton.index(name)]
            np.testing.assert_allclose(got, _to_z_up(p) * scale, atol=1e-9, err_msg=name)


def test_asf_found_beside_amc(tmp_path):
    """``SS_TT.amc`` finds ``SS.asf``; ``x.amc`` finds ``x.asf``; otherwise a clear error."""
    amc_text = (DATA / "chain.amc").read_text()
    (tmp_path / "07.asf").write_text(CHAIN_ASF.read_text())
    (tmp_path / "07_03.amc").write_text(amc_text)
    m = load_motion(tmp_path / "07_03.amc")
    assert m.meta["asf"] == str(tmp_path / "07.asf")
    (tmp_path / "walk.asf").write_text(CHAIN_ASF.read_text())
    (tmp_path / "walk.amc").write_text(amc_text)
    assert load_motion(tmp_path / "walk.amc").meta["asf"] == str(tmp_path / "walk.asf")
    (tmp_path / "lonely.amc").write_text(amc_text)
    with pytest.raises(MotionFormatError, match="lonely.asf"):
        load_motion(tmp_path / "lonely.amc")


CHAIN_AMC = (DATA / "chain.amc").read_text()
CHAIN_TEXT = CHAIN_ASF.read_text()


@pytest.mark.parametrize(
    ("asf_text", "amc_text", "message", "where"),
    [
        ("", CHAIN_AMC, "empty", "asf"),
        (
            CHAIN_TEXT.replace(":hierarchy", ":hierarchyy"),
            CHAIN_AMC,
            "unknown ASF section",
            "asf:36",
        ),
        (CHAIN_TEXT.split(":hierarchy")[0], CHAIN_AMC, "missing section :hierarchy", "asf"),
        (CHAIN_TEXT.replace("length 3", "length three"), CHAIN_AMC, "non-numeric", "asf:30"),
        (CHAIN_TEXT.replace("length 3", "length nan"), CHAIN_AMC, "NaN", "asf:30"),
        (CHAIN_TEXT.replace("dof rx rz", "dof rx rw"), CHAIN_AMC, "dof", "asf:32"),
        (
            CHAIN_TEXT.replace("     id 2\n", "     idd 2\n"),
            CHAIN_AMC,
            "unknown bone keyword",
            "asf:27",
        ),
        (CHAIN_TEXT.replace("    a b\n", ""), CHAIN_AMC, "not in the hierarchy", "asf:26"),
        (CHAIN_TEXT.replace("    a b\n", "    a c\n"), CHAIN_AMC, "unknown bone 'c'", "asf:39"),
        (CHAIN_TEXT.rsplit("  end", 1)[0], CHAIN_AMC, "begin ... end", "asf:37"),
        (CHAIN_TEXT.replace("(-10.0 , 10.0)", "(10.0 , -10.0)"), CHAIN_AMC, "reversed", "asf:33"),
        (CHAIN_TEXT, "", "no frames", "amc"),
        (CHAIN_TEXT, CHAIN_AMC.replace("\na 90\n", "\na 90 1\n"), "needs 1 values, got 2", "amc:8"),
        (CHAIN_TEXT, CHAIN_AMC.replace("b 0 90", "b 0 x"), "non-numeric", "amc:9"),
        (CHAIN_TEXT, CHAIN_AMC.replace("b 0 90", "b 0 nan"), "NaN", "amc:9"),
        (CHAIN_TEXT, CHAIN_AMC.replace("\na 90\n", "\nc 90\n"), "unknown bone 'c'", "amc:8"),
        (CHAIN_TEXT, CHAIN_AMC.replace("\n3\n", "\n4\n"), "out of sequence", "amc:10"),
        (CHAIN_TEXT, CHAIN_AMC + "4\n", "no data", "amc:12"),
        (CHAIN_TEXT, CHAIN_AMC + "4\nroot 1 2\n", "needs 6 values, got 2", "amc:13"),
        (
            CHAIN_TEXT,
            CHAIN_AMC.replace("\na 90\n", "\na 90\na 90\n"),
            "twice in one frame",
            "amc:9",
        ),
        (CHAIN_TEXT, "root 0 0 0 0 0 0\n", "expected a frame number", "amc:1"),
        (CHAIN_TEXT, CHAIN_AMC + ":DEGREES\n", "unexpected AMC keyword", "amc:12"),
    ],
)
def test_malformed_files_name_file_and_line(tmp_path, asf_text, amc_text, message, where):
    (tmp_path / "s.asf").write_text(asf_text)
    (tmp_path / "s.amc").write_text(amc_text)
    with pytest.raises(MotionFormatError, match=message) as err:
        load_motion(tmp_path / "s.amc")
    suffix, _, line = where.partition(":")
    assert err.value.path == str(tmp_path / f"s.{suffix}")
    assert err.value.line == (int(line) if line else None)


@pytest.mark.skipif(
    importlib.util.find_spec("avatarsim.avatar_models.formats.bvh") is None,
    reason="BVH writer not present",
)
def test_amc_to_bvh_roundtrip(tmp_path):
    m = load_motion(DATA / "chain.amc", asf=CHAIN_ASF)
    out = save_motion(m, tmp_path / "chain.bvh")
    back = load_motion(out, unit="cm")
    assert back.n_frames == m.n_frames
    assert back.fps == pytest.approx(m.fps)
    np.testing.assert_allclose(back.global_positions(), m.global_positions(), atol=1e-5)


def test_softimage_order_preset_position_and_dof_order_worked_by_hand():
    """Facts of the format, worked on paper (no FK code, no parsed values): the VICON/CMU
    notes on the ASF ("Acclaim Format - ASF line Details", graphics.cs.cmu.edu/nsp/course/
    cs229/info/ACCLAIMdef.html) say the root's ``order`` line gives both the order of the
    AMC's root values and the sequence in which the root rotations are applied about fixed
    global axes, and that the root's pre-set ``position`` offsets all the motion. A bone's
    rotation is ``C M C^-1`` about its ``axis`` frame C (Lander 1998), its dofs applied in
    the order listed like the root's. ``length 0.45``: 1 unit = 1/0.45 inch.

    softimage.asf, Y up, file units: root pre-set at (1,0,0); bone up = 4 along +Y, dofs
    ``rz rx``; bone side = 2 along +X, C = Rz(90) (C's x axis is world +Y), dof ``rx``.
    Rz(90): (x,y,z) -> (-y,x,z); Ry(90): (x,y,z) -> (z,y,-x); Rx(90): (x,y,z) -> (x,-z,y).

    1. rest: root (1,0,0), up tip (1,4,0), side tip (3,4,0).
    2. root rz 90: up (0,4,0) -> (-4,0,0), side (2,0,0) -> (0,2,0): (-3,0,0), (-3,2,0).
    3. root rz 90 THEN ry 90 (order line): up (0,4,0) -Rz-> (-4,0,0) -Ry-> (0,0,4); side
       (2,0,0) -Rz-> (0,2,0) -Ry-> (0,2,0): (1,0,4), (1,2,4). (Ry first would give
       up -> (-4,0,0): the test tells the orders apart.)
    4. up rz 90 THEN rx 90: up (0,4,0) -Rz-> (-4,0,0) -Rx-> (-4,0,0); side (2,0,0) -Rz->
       (0,2,0) -Rx-> (0,0,2): (-3,0,0), (-3,0,2). (rx first: up tip (1,0,4).)
    5. root tz 5 (plus the pre-set): (1,0,5); side rx 90 turns about C's x = world +Y:
       (2,0,0) -> (0,0,-2): up tip (1,4,5), side tip (1,4,3).
    """
    m = load_motion(DATA / "softimage.amc", asf=DATA / "softimage.asf")
    assert m.skeleton.names == ("root", "up", "side", "side_end")
    # joint "up" sits where bone up starts (the root), "side" at up's tip, "side_end" at
    # side's tip.
    expected = np.array(
        [
            [[1, 0, 0], [1, 0, 0], [1, 4, 0], [3, 4, 0]],
            [[1, 0, 0], [1, 0, 0], [-3, 0, 0], [-3, 2, 0]],
            [[1, 0, 0], [1, 0, 0], [1, 0, 4], [1, 2, 4]],
            [[1, 0, 0], [1, 0, 0], [-3, 0, 0], [-3, 0, 2]],
            [[1, 0, 5], [1, 0, 5], [1, 4, 5], [1, 4, 3]],
        ],
        dtype=float,
    )
    metres = INCH / 0.45
    np.testing.assert_allclose(m.global_positions(), _to_z_up(expected) * metres, atol=1e-9)
