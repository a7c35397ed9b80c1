"""Bad input: each group exits 2 with one accurate line on stderr, is checked before any
work, writes nothing half-way and never deletes a user's file."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from avatarsim.avatar_models.formats import save_motion
from avatarsim.avatar_models.generator import generate
from avatarsim.scripts.cli import app
from tests.conftest import require

runner = CliRunner()


def cmu_09_01(mocap_dir: Path) -> Path:
    """CMU 09_01 (a run with a T-pose first frame), under :func:`require`."""
    clip = mocap_dir / "cmu" / "09_01.bvh"
    require(clip.is_file(), f"{clip} is absent")
    return clip


def bad(args: list[str], *expected: str) -> None:
    """``args`` exit 2 with one line on stderr holding every ``expected`` text."""
    result = runner.invoke(app, args)
    assert result.exit_code == 2, (result.exit_code, result.output)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    for text in expected:
        assert text in lines[0], (text, lines[0])
    assert "Traceback" not in result.output


def no_partials(folder: Path) -> None:
    left = [p.name for p in folder.iterdir() if ".partial-" in p.name or ".old-" in p.name]
    assert not left, left


@pytest.fixture
def scenario(tmp_path) -> Path:
    sc = tmp_path / "s.toml"
    sc.write_text('name = "s"\n[motion]\nduration_s = 0.5\n')
    return sc


@pytest.fixture
def clip(tmp_path) -> Path:
    return save_motion(generate("walk", duration_s=0.5, fps=30.0), tmp_path / "walk.npz")


# -- output paths -------------------------------------------------------------------------
def commands_with(kind: str, target: str, scenario: Path) -> list[list[str]]:
    """Every command, with ``target`` as its ``--out`` (kind "out") or ``--json``."""
    if kind == "out":
        return [
            ["check", "builtin:walk", "--out", target],
            ["control", "builtin:walk", "--out", target],
            ["render", "fisheye", "builtin:walk", "--out", target],
            ["eval", "protocol", "coolmoves", "--out", target],
            ["run", str(scenario), "--out", target],
            ["demo", "--out", target],
            ["convert", "builtin:walk", str(Path(target) / "x.bvh")],
        ]
    return [
        ["info", "builtin:walk", "--json", target],
        ["convert", "builtin:walk", str(Path(target).parent / "ok.bvh"), "--json", target],
        ["check", "builtin:walk", "--json", target],
        ["control", "builtin:walk", "--json", target],
        ["render", "fisheye", "builtin:walk", "--json", target],
        ["eval", "protocol", "coolmoves", "--json", target],
        ["run", str(scenario), "--json", target],
        ["demo", "--json", target],
        ["bench", "--json", target],
    ]


def test_out_that_is_a_file_or_below_a_file_exits_2_before_any_work(tmp_path, scenario):
    blocker = tmp_path / "file.txt"
    blocker.write_text("mine")
    for args in commands_with("out", str(blocker / "sub"), scenario):
        bad(args, "is a file, not a folder")
    for args in commands_with("out", str(blocker), scenario)[:-1]:  # convert: below a file
        bad(args, "is a file")
    assert blocker.read_text() == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file.txt", "s.toml"]


def test_json_that_is_a_folder_or_below_a_file_exits_2_before_any_work(tmp_path, scenario):
    folder = tmp_path / "folder"
    folder.mkdir()
    for args in commands_with("json", str(folder), scenario):
        bad(args, "--json", "is a folder")
    blocker = tmp_path / "file.txt"
    blocker.write_text("mine")
    for args in commands_with("json", str(blocker / "r.json"), scenario):
        bad(args, "--json", "is a file, not a folder")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file.txt", "folder", "s.toml"]
    assert not list(folder.iterdir())


@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs Linux /proc")
def test_unwritable_out_and_json_exit_2(tmp_path, scenario):
    # /proc refuses new entries even to root, unlike a chmod-ed folder.
    target = "/proc/avatarsim-test/out"
    for args in commands_with("out", target, scenario) + commands_with("json", target, scenario):
        bad(args, "cannot write in /proc")


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_read_only_folder_exits_2(tmp_path, scenario):
    ro = tmp_path / "ro"
    ro.mkdir(mode=0o555)
    bad(["check", "builtin:walk", "--out", str(ro / "o")], "cannot write")
    bad(["info", "builtin:walk", "--json", str(ro / "i.json")], "cannot write")


# -- data loss and leftovers ---------------------------------------------------------------
@pytest.mark.parametrize("command", ["control", "run"])
def test_out_holding_a_users_file_is_refused_and_kept(tmp_path, scenario, command):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("my notes")
    target = (
        ["control", "builtin:walk", "--plain"] if command == "control" else ["run", str(scenario)]
    )
    bad([*target, "--out", str(out)], "notes.txt", "not written by `avatarsim")
    assert (out / "notes.txt").read_text() == "my notes"
    assert [p.name for p in out.iterdir()] == ["notes.txt"]
    no_partials(tmp_path)


def test_control_replaces_its_own_output_but_not_a_file_added_to_it(tmp_path, clip):
    out = tmp_path / "o"
    args = ["control", str(clip), "--plain", "--seconds", "0.3", "--out", str(out)]
    first = runner.invoke(app, args)
    assert first.exit_code in (0, 1), first.output
    assert (out / "control.json").is_file() and (out / ".avatarsim-output.json").is_file()
    marker = json.loads((out / ".avatarsim-output.json").read_text())
    assert marker["command"] == "control" and "control.json" in marker["files"]
    again = runner.invoke(app, args)  # a previous output of control: replaced
    assert again.exit_code == first.exit_code, again.output
    (out / "keep.txt").write_text("mine")
    bad(args, "keep.txt")
    assert (out / "keep.txt").read_text() == "mine"
    # Another command's output is not control's to replace either.
    bad(["run", str(tmp_path / "none.toml"), "--out", str(out)], "output of `avatarsim control`")
    no_partials(tmp_path)


@pytest.mark.parametrize("failure", [RuntimeError, KeyboardInterrupt, SystemExit])
def test_no_partial_folder_is_left_after_a_failure(tmp_path, scenario, monkeypatch, failure):
    from avatarsim.scripts.stages import physics

    def broken(ctx):
        raise failure("stopped")

    monkeypatch.setattr(physics, "run", broken)
    out = tmp_path / "o"
    result = runner.invoke(app, ["run", str(scenario), "--out", str(out)])
    assert result.exit_code != 0
    assert not out.exists()
    no_partials(tmp_path)


def test_atomic_dir_cleans_up_and_keeps_the_old_output_when_the_block_fails(tmp_path):
    from avatarsim.scripts.results import atomic_dir

    out = tmp_path / "o"
    with atomic_dir(out, "control") as partial:
        (partial / "a.txt").write_text("1")
    with pytest.raises(KeyboardInterrupt), atomic_dir(out, "control") as partial:
        (partial / "a.txt").write_text("2")
        raise KeyboardInterrupt
    assert (out / "a.txt").read_text() == "1"
    assert oct(out.stat().st_mode & 0o777) == oct(0o777 & ~_umask())
    no_partials(tmp_path)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


# -- numbers -------------------------------------------------------------------------------
def test_negative_seed_exits_2(tmp_path, scenario):
    bad(["info", "builtin:walk", "--seed", "-1"], "--seed", "-1")
    bad(["run", str(scenario), "--seed", "-5", "--out", str(tmp_path / "o")], "--seed")
    scenario.write_text("seed = -3\n")
    bad(["run", str(scenario), "--out", str(tmp_path / "o")], "seed must be >= 0, got -3")
    assert not (tmp_path / "o").exists()


BVH = (
    "HIERARCHY\nROOT Hips\n{{\nOFFSET 0 0 0\nCHANNELS 6 Xposition Yposition Zposition "
    "Zrotation Xrotation Yrotation\nJOINT Head\n{{\nOFFSET 0 90 0\nCHANNELS 3 Zrotation "
    "Xrotation Yrotation\nEnd Site\n{{\nOFFSET 0 80 0\n}}\n}}\n}}\nMOTION\nFrames: {n}\n"
    "Frame Time: {ft}\n{rows}"
)


def bvh(tmp_path: Path, n: int = 3, ft: str = "0.0333333", name: str = "b.bvh") -> Path:
    path = tmp_path / name
    rows = "".join(f"0 90 {i} 0 0 0 0 0 0\n" for i in range(n))
    path.write_text(BVH.format(n=n, ft=ft, rows=rows))
    return path


@pytest.mark.parametrize("ft", ["1e-300", "1e300", "0.00001", "5"])
def test_absurd_frame_time_exits_2(tmp_path, ft):
    bad(["info", str(bvh(tmp_path, ft=ft))], "Frame Time", "fps")


def test_absurd_numbers_exit_2(tmp_path, clip):
    out = str(tmp_path / "o")
    bad(["convert", str(clip), str(tmp_path / "x.bvh"), "--fps", "1e9"], "--fps", "1-1000")
    bad(["convert", str(clip), str(tmp_path / "x.bvh"), "--fps", "nan"], "--fps")
    bad(["control", str(clip), "--seconds", "inf", "--out", out], "--seconds", "at most 600")
    bad(["control", str(clip), "--samples", "100000", "--out", out], "--samples")
    bad(["render", "fisheye", str(clip), "--duration-s", "inf", "--out", out], "--duration-s")
    bad(
        ["render", "fisheye", str(clip), "--size", "40000,30000", "--out", out], "--size", "16-4096"
    )
    bad(["render", "fisheye", str(clip), "--fov", "nan,90", "--out", out], "--fov")
    bad(["eval", "protocol", "coolmoves", "--duration", "inf", "--out", out], "--duration")
    bad(
        ["eval", "protocol", "coolmoves", "--correlation-threshold", "nan", "--out", out], "-1 to 1"
    )
    assert not (tmp_path / "o").exists() and not (tmp_path / "x.bvh").exists()


@pytest.mark.parametrize(
    "toml, expected",
    [
        ("[report]\npicture_frames = 100000\n", "report.picture_frames must be >= 1 and <= 50"),
        ("[report]\ngif_fps = 0\n", "report.gif_fps"),
        ("[physics]\ncontact_height_m = inf\n", "contact_height_m"),
        ("[physics]\ncontact_height_m = 3.0\n", "contact_height_m"),
        ("[thresholds]\nframes = { min = 10, max = 5 }\n", "min 10 is above max 5"),
        ("[motion]\nduration_s = inf\n", "motion.duration_s"),
        ("[motion]\nfps = 1e9\n", "motion.fps"),
        ("[control]\nseconds = 1e6\n", "control.seconds"),
        ("[body]\nmass_kg = 1e9\n", "body.mass_kg"),
    ],
)
def test_absurd_scenario_numbers_exit_2(tmp_path, toml, expected):
    sc = tmp_path / "s.toml"
    sc.write_text(toml)
    bad(["run", str(sc), "--out", str(tmp_path / "o")], expected)
    assert not (tmp_path / "o").exists()


def test_absurd_check_config_exits_2(tmp_path, clip):
    cfg = tmp_path / "c.toml"
    cfg.write_text("contact_height_m = inf\n")
    bad(
        ["check", str(clip), "--config", str(cfg), "--out", str(tmp_path / "o")],
        "contact_height_m must be a finite number",
    )


# -- motions that are no input for physics -------------------------------------------------
def test_a_one_frame_clip_is_too_short(tmp_path):
    one = bvh(tmp_path, n=1)
    out = str(tmp_path / "o")
    bad(["check", str(one), "--out", out], "too short", "1 frame")
    bad(["control", str(one), "--out", out], "too short")
    sc = tmp_path / "s.toml"
    sc.write_text(f'[motion]\nsource = "{one}"\nfps = 30.0\n')
    bad(["run", str(sc), "--out", out], "too short")
    sc.write_text("[motion]\nduration_s = 0.01\n")
    bad(["run", str(sc), "--out", out], "too short")
    assert not (tmp_path / "o").exists()
    info = runner.invoke(app, ["info", str(one)])  # info describes it all the same
    assert info.exit_code == 0, info.output


def test_a_wrong_unit_giving_no_persons_height_exits_2(tmp_path):
    path = save_motion(generate("walk", duration_s=0.5), tmp_path / "w.bvh")  # written in cm
    bad(["check", str(path), "--unit", "mm", "--out", str(tmp_path / "o")], "--unit cm", "tall")
    bad(["control", str(path), "--unit", "inch", "--out", str(tmp_path / "o")], "--unit cm")
    bad(["convert", str(path), str(tmp_path / "x.npz"), "--unit", "m"], "--unit cm")
    info = runner.invoke(app, ["info", str(path), "--unit", "mm"])
    assert info.exit_code == 0 and "warning" in info.output and "--unit cm" in info.output


@pytest.mark.mocap
def test_cmu_in_millimetres_names_the_cmu_unit(mocap_dir):
    clip = cmu_09_01(mocap_dir)
    bad(["check", str(clip), "--unit", "mm"], "0.0", "--unit cmu")


# -- malformed files and messages ----------------------------------------------------------
def _npz_with(tmp_path: Path, **changes) -> Path:
    path = save_motion(generate("wave", duration_s=0.2), tmp_path / "w.npz")
    with np.load(path) as data:
        arrays = {k: data[k] for k in data.files}
    arrays.update(changes)
    np.savez(path, **arrays)
    return path


def test_npz_with_a_list_meta_or_wrong_is_site_exits_2(tmp_path):
    bad(["info", str(_npz_with(tmp_path, meta_json=np.array("[1, 2]")))], "meta_json", "list")
    bad(["info", str(_npz_with(tmp_path, is_site=np.zeros(3, bool)))], "is_site")


def test_rich_markup_in_errors_is_shown_as_written(tmp_path):
    sc = tmp_path / "s.toml"
    sc.write_text("[motion]\nspeed = 1.0\n")
    bad(["run", str(sc)], "unknown key 'speed' in [motion]")
    bad(["info", str(tmp_path / "[bold]x.bvh")], "[bold]x.bvh", "no such file")


def test_amc_without_asf_gives_advice_a_user_can_follow(tmp_path):
    amc = tmp_path / "01_01.amc"
    amc.write_text(":FULLY-SPECIFIED\n:DEGREES\n1\nroot 0 0 0 0 0 0\n")
    result = runner.invoke(app, ["info", str(amc)])
    assert result.exit_code == 2
    assert "asf=" not in result.stderr.replace("asf=...", "")
    assert "same folder, named 01_01.asf or 01.asf" in result.stderr


def test_options_that_would_be_ignored_exit_2(tmp_path):
    out = str(tmp_path / "o")
    for device, option, value in (
        ("kinect-v2", "--fov", "90,60"),
        ("azure-kinect", "--size", "8,8"),
    ):
        result = runner.invoke(app, ["render", device, "builtin:walk", option, value, "--out", out])
        assert result.exit_code == 2 and f"No such option: {option}" in result.output
        assert not Path(out).exists()
    bad(["info", "builtin:walk", "--unit", "mm"], "--unit", "builtin:walk")
    sc = tmp_path / "s.toml"
    sc.write_text('[motion]\nunit = "cm"\n')
    bad(["run", str(sc), "--out", out], "motion.unit")


def test_degenerate_skeleton_gives_one_line_and_no_numpy_warning(tmp_path):
    path = tmp_path / "zero.bvh"
    path.write_text(bvh(tmp_path, n=3).read_text().replace("OFFSET 0 90 0", "OFFSET 0 0 0"))
    path.write_text(path.read_text().replace("OFFSET 0 80 0", "OFFSET 0 0 0"))
    bad(["check", str(path), "--out", str(tmp_path / "o")], "no size")


def test_convert_writes_files_with_the_umask_mode(tmp_path, clip):
    old = os.umask(0o022)
    try:
        for name in ("a.bvh", "a.npz"):
            result = runner.invoke(
                app, ["convert", str(clip), str(tmp_path / name), "--json", str(tmp_path / "j")]
            )
            assert result.exit_code == 0, result.output
            assert (tmp_path / name).stat().st_mode & 0o777 == 0o644
            assert (tmp_path / "j").stat().st_mode & 0o777 == 0o644
        os.umask(0o077)
        assert runner.invoke(app, ["convert", str(clip), str(tmp_path / "b.bvh")]).exit_code == 0
        assert (tmp_path / "b.bvh").stat().st_mode & 0o777 == 0o600
    finally:
        os.umask(old)


# -- the T-pose the cgspeed CMU conversions put before the take ----------------------------
def test_a_prepended_rest_pose_frame_is_dropped_and_reported(tmp_path):
    from avatarsim.avatar_models.formats import load_motion

    walk = generate("walk", duration_s=0.5, fps=120.0)
    rest = walk[:1].replace(local_rot=np.tile([1.0, 0.0, 0.0, 0.0], (1, walk.skeleton.n_joints, 1)))
    path = save_motion(
        type(walk).concatenate([rest, walk], continue_root=False), tmp_path / "t.bvh"
    )
    read = load_motion(path)
    assert read.n_frames == walk.n_frames and read.meta["dropped_frames"]["frames"] == [0]
    assert np.allclose(read.root_pos, walk.root_pos, atol=1e-6)
    kept = load_motion(path, drop_rest_frame=False)
    assert kept.n_frames == walk.n_frames + 1 and "dropped_frames" not in kept.meta
    plain = load_motion(save_motion(walk, tmp_path / "w.bvh"))
    assert plain.n_frames == walk.n_frames and "dropped_frames" not in plain.meta
    info = runner.invoke(app, ["info", str(path), "--json", str(tmp_path / "i.json")])
    assert info.exit_code == 0 and "dropped frame(s) [0]" in info.output
    assert json.loads((tmp_path / "i.json").read_text())["dropped_frames"]["frames"] == [0]


@pytest.mark.mocap
def test_cmu_09_01_loses_its_t_pose_frame_and_its_residual_spike(tmp_path, mocap_dir):
    from avatarsim.avatar_models.formats import load_motion

    clip = cmu_09_01(mocap_dir)
    m = load_motion(clip)
    raw = load_motion(clip, drop_rest_frame=False)
    assert raw.n_frames == 149 and m.n_frames == 148
    assert "rest pose" in m.meta["dropped_frames"]["reason"]
    assert np.allclose(m.local_rot, raw.local_rot[1:])
    out = tmp_path / "o"
    result = runner.invoke(app, ["check", str(clip), "--out", str(out)])
    assert result.exit_code in (0, 1), result.output
    rows = np.genfromtxt(out / "check.csv", delimiter=",", names=True)
    residual = [n for n in rows.dtype.names if n.startswith("residual")][0]
    assert rows[residual][:5].max() < 3.0  # was a 9.3 body-weight spike from the T-pose


def test_an_output_from_before_the_marker_is_still_replaced(tmp_path):
    from avatarsim.avatar_models.errors import AvatarsimError
    from avatarsim.scripts.results import atomic_dir

    out = tmp_path / "t"
    out.mkdir()
    (out / "tracking.json").write_text('{"mode": "plain"}')  # as `track` wrote them then
    (out / "tracking.csv").write_text("a\n")
    with atomic_dir(out, "control") as partial:
        (partial / "control.json").write_text('{"mode": "search"}')
    assert sorted(p.name for p in out.iterdir()) == [".avatarsim-output.json", "control.json"]
    run = tmp_path / "r"
    (run / "physics").mkdir(parents=True)
    (run / "physics" / "check.csv").write_text("x")
    outputs = {"results_json": "results.json", "junit_xml": "junit.xml", "p": "physics/check.csv"}
    (run / "results.json").write_text(
        json.dumps({"scenario": "s", "versions": {}, "outputs": outputs})
    )
    (run / "junit.xml").write_text("<x/>")
    (run / "mine.txt").write_text("mine")
    with pytest.raises(AvatarsimError, match="mine.txt"), atomic_dir(run, "run"):
        pass
    (run / "mine.txt").unlink()
    (run / "empty").mkdir()  # a user's empty folder or link to one is no file of ours either
    with pytest.raises(AvatarsimError, match="empty"), atomic_dir(run, "run"):
        pass
    (run / "empty").rmdir()
    (run / "link").symlink_to(tmp_path)
    with pytest.raises(AvatarsimError, match="link"), atomic_dir(run, "run"):
        pass
    (run / "link").unlink()
    with atomic_dir(run, "run") as partial:
        (partial / "results.json").write_text("{}")
    assert sorted(p.name for p in run.iterdir()) == [".avatarsim-output.json", "results.json"]


def test_a_file_system_refusal_mid_run_exits_2_not_3(tmp_path, monkeypatch):
    import errno

    import avatarsim.avatar_models.formats as formats

    def full(motion, path, **options):
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    monkeypatch.setattr(formats, "save_motion", full)
    bad(["convert", "builtin:walk", str(tmp_path / "x.bvh")], "x.bvh", "No space left")


def test_numpy_warnings_never_come_before_the_error_line(tmp_path, monkeypatch):
    import avatarsim.avatar_models.formats as formats
    from avatarsim.avatar_models.errors import MotionFormatError

    def noisy(path, **options):
        with np.errstate(divide="warn"):
            np.log(np.zeros(1))  # RuntimeWarning: divide by zero
        raise MotionFormatError("broken", path)

    monkeypatch.setattr(formats, "load_motion", noisy)
    bad(["info", str(tmp_path / "a.bvh")], "broken")  # one line: the warning is dropped

    def noisy_ok(path, **options):
        with np.errstate(divide="warn"):
            np.log(np.zeros(1))
        return generate("wave", duration_s=0.2)

    monkeypatch.setattr(formats, "load_motion", noisy_ok)
    result = runner.invoke(app, ["info", str(tmp_path / "a.bvh")])
    assert result.exit_code == 0
    assert result.stderr.count("warning: RuntimeWarning: divide by zero") == 1


def test_out_that_is_the_working_folder_or_holds_the_export_exits_2(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for args in (
        ["control", "builtin:walk", "--plain", "--seconds", "0.5", "--out", "."],
        ["control", "builtin:walk", "--plain", "--seconds", "0.5", "--out", "o", "--export", "o"],
        ["control", "builtin:walk", "--plain", "--seconds", "0.5", "--out", "o", "--export", "o/v"],
    ):
        result = runner.invoke(app, args)
        assert result.exit_code == 2, (args, result.output)
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_a_mocap_motion_without_a_mocap_folder_names_the_variable(monkeypatch):
    monkeypatch.delenv("AVATARSIM_MOCAP", raising=False)
    bad(["info", "mocap:cmu/09_01.bvh"], "mocap:cmu/09_01.bvh", "AVATARSIM_MOCAP")


@pytest.mark.mocap
def test_a_mocap_motion_is_read_from_the_mocap_folder(mocap_dir, monkeypatch):
    clip = cmu_09_01(mocap_dir)
    monkeypatch.setenv("AVATARSIM_MOCAP", str(mocap_dir))
    by_name = runner.invoke(app, ["info", "mocap:cmu/09_01.bvh"])
    by_path = runner.invoke(app, ["info", str(clip)])
    assert by_name.exit_code == 0, by_name.output
    assert by_name.stdout.replace("mocap:cmu/09_01.bvh", str(clip)) == by_path.stdout
