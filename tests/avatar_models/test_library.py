"""Motion library: indexing the three naming schemes, annotations, queries, splits, loading."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from avatarsim.avatar_models.errors import MotionValueError
from avatarsim.avatar_models.library import MotionLibrary, parse_free_form

DATA = Path(__file__).resolve().parents[1] / "data" / "asf_amc"


@pytest.fixture()
def folder(tmp_path: Path) -> Path:
    cmu = tmp_path / "cmu"
    cmu.mkdir()
    for name in ("06_06.bvh", "06_07.bvh", "125_01.amc", "125.asf"):
        (cmu / name).touch()
    (cmu / "CLIPS.md").write_text(
        "| clip | activity (Table 1) | subject | frames |\n|---|---|---|---|\n"
        "| 06_06 | basketball | 6 | 403 |\n| 125_01 | swimming (breaststroke) | 125 | 740 |\n"
    )
    bandai = tmp_path / "bandai" / "dataset-1"
    (bandai / "data").mkdir(parents=True)
    (bandai / "cfg").mkdir()
    (bandai / "cfg" / "content_label.txt").write_text("dataset-1_walk\ndataset-1_kick\n")
    (bandai / "cfg" / "style_label.txt").write_text("dataset-1_normal\ndataset-1_happy\n")
    for stem, ids in (
        ("walk_happy_001", (0, 1)),
        ("walk_happy_002", (0, 1)),
        ("kick_normal_001", (1, 0)),
    ):
        (bandai / "data" / f"dataset-1_{stem}.bvh").touch()
        json.dump(
            {"content": ids[0], "style": ids[1]},
            (bandai / "data" / f"dataset-1_{stem}.json").open("w"),
        )
    # The JSON annotation wins over a misleading name.
    (bandai / "data" / "dataset-1_wlk_normal_003.bvh").touch()
    json.dump(
        {"content": 0, "style": 0}, (bandai / "data" / "dataset-1_wlk_normal_003.json").open("w")
    )
    free = tmp_path / "mine"
    free.mkdir()
    for name in ("walk_fast_subject3_take2.bvh", "jog-02.bvh", "Running_S12_T3.npz", "notes.txt"):
        (free / name).touch()
    (free / "index.toml").write_text('[clips.jog-02]\nsubject = "7"\n')
    return tmp_path


def test_index_labels_all_schemes(folder):
    lib = MotionLibrary.index(folder)
    assert len(lib) == 10  # .asf and .txt are not clips
    by_name = {c.name: c for c in lib}
    c = by_name["06_06"]
    assert (c.activity, c.subject, c.take, c.source, c.format) == (
        "basketball",
        "6",
        6,
        "cmu",
        "bvh",
    )
    c = by_name["125_01"]
    assert (c.activity, c.style, c.subject, c.format) == ("swimming", "breaststroke", "125", "amc")
    assert by_name["06_07"].activity is None and by_name["06_07"].subject == "6"
    c = by_name["dataset-1_kick_normal_001"]
    assert (c.activity, c.style, c.take, c.subject, c.source) == (
        "kick",
        "normal",
        1,
        None,
        "bandai-dataset-1",
    )
    assert by_name["dataset-1_wlk_normal_003"].activity == "walk"
    c = by_name["walk_fast_subject3_take2"]
    assert (c.activity, c.style, c.subject, c.take) == ("walk", "fast", "3", 2)
    c = by_name["jog-02"]
    assert (c.activity, c.subject, c.take) == ("jog", "7", 2)  # subject from index.toml
    assert (by_name["Running_S12_T3"].activity, by_name["Running_S12_T3"].subject) == ("run", "12")


def test_queries_and_label_lists(folder):
    lib = MotionLibrary.index(folder)
    assert lib.activities() == ["basketball", "jog", "kick", "run", "swimming", "walk"]
    assert lib.subjects() == ["12", "125", "3", "6", "7"]
    assert lib.styles() == ["breaststroke", "fast", "happy", "normal"]
    assert {c.name for c in lib.query(activity="walk")} == {
        "dataset-1_walk_happy_001",
        "dataset-1_walk_happy_002",
        "dataset-1_wlk_normal_003",
        "walk_fast_subject3_take2",
    }
    assert len(lib.query(activity=["walk", "kick"], style="happy")) == 2
    assert [c.name for c in lib.query(subject="06", take=6)] == ["06_06"]
    assert [c.name for c in lib.query(subject=6, take="6")] == ["06_06"]
    assert lib.query(activity="fly") == []
    assert len(lib.query()) == len(lib) == len(list(lib))


def test_split_cross_subject_and_trial(folder):
    lib = MotionLibrary.index(folder)
    folds = list(lib.split(by="subject"))
    assert [f.held_out for f in folds] == lib.subjects()
    for fold in folds:
        assert all(c.subject == fold.held_out for c in fold.test)
        assert all(c.subject != fold.held_out for c in fold.train)
        assert len(fold.train) + len(fold.test) == len(lib)
    takes = list(lib.split(by="take"))
    assert sorted(f.held_out for f in takes) == [1, 2, 3, 6, 7]
    bandai = MotionLibrary(lib.query(source="bandai-dataset-1"))
    with pytest.raises(MotionValueError, match="at least 2 subjects"):
        list(bandai.split(by="subject"))


def test_free_form_heuristic():
    assert parse_free_form("jogging_slow_02") == {
        "activity": "jog",
        "subject": None,
        "style": "slow",
        "take": 2,
    }
    assert parse_free_form("happy-dance-subject-4")["activity"] == "dance"
    assert parse_free_form("actor2 swim trial 5") == {
        "activity": "swim",
        "subject": "2",
        "style": None,
        "take": 5,
    }
    assert parse_free_form("calibration")["activity"] == "calibration"  # unknown word: first word


def test_clip_load_carries_labels(tmp_path):
    (tmp_path / "chain.asf").write_text((DATA / "chain.asf").read_text())
    (tmp_path / "wave_subject2_take1.amc").write_text((DATA / "chain.amc").read_text())
    clip = MotionLibrary.index(tmp_path).clips[0]
    motion = clip.load(asf=tmp_path / "chain.asf", fps=60)
    assert motion.n_frames == 3 and motion.fps == 60
    assert (motion.meta["activity"], motion.meta["subject"], motion.meta["take"]) == (
        "wave",
        "2",
        1,
    )


@pytest.mark.mocap
def test_index_shared_mocap(mocap_dir):
    lib = MotionLibrary.index(mocap_dir)
    d1 = MotionLibrary(lib.query(source="bandai-dataset-1"))
    d2 = MotionLibrary(lib.query(source="bandai-dataset-2"))
    cmu = MotionLibrary(lib.query(source="cmu"))
    assert (len(d1), len(d2), len(cmu)) == (174, 210, 9)
    # dataset-1 as shipped: 16 contents in names (the README counts 20), 15 styles.
    assert len(d1.activities()) == 16 and len(d1.styles()) == 15
    assert len(d2.activities()) == 10 and len(d2.styles()) == 7
    assert len(d2.query(activity="walk", style="normal")) == 3
    assert cmu.activities() == ["basketball", "climbing ladder", "running", "swimming"]
    assert len(cmu.query(activity="running")) == 3 and len(cmu.subjects()) == 9
    assert len(list(cmu.split(by="subject"))) == 9
