"""Real mocap is found where the user says (option, then ``$AVATARSIM_MOCAP``), never by
where the code lives; a folder named but absent is a user error."""

from __future__ import annotations

import pytest

from avatarsim.avatar_models import AvatarsimError
from avatarsim.avatar_models.mocap_dir import (
    MOCAP_ENV,
    MocapUnset,
    is_mocap_source,
    mocap_dir,
    resolve_mocap_source,
)


def test_option_then_environment_then_none(tmp_path, monkeypatch):
    option, env = tmp_path / "option", tmp_path / "env"
    option.mkdir()
    env.mkdir()
    monkeypatch.delenv(MOCAP_ENV, raising=False)
    assert mocap_dir() is None
    monkeypatch.setenv(MOCAP_ENV, str(env))
    assert mocap_dir() == env
    assert mocap_dir(option) == option


@pytest.mark.parametrize("via", ["option", "environment"])
def test_a_missing_folder_is_a_user_error_naming_it(tmp_path, monkeypatch, via):
    missing = tmp_path / "nowhere"
    monkeypatch.setenv(MOCAP_ENV, str(missing))
    with pytest.raises(AvatarsimError, match="nowhere"):
        mocap_dir(missing if via == "option" else None)


def test_a_mocap_source_names_a_file_inside_the_folder(tmp_path, monkeypatch):
    monkeypatch.setenv(MOCAP_ENV, str(tmp_path))
    assert resolve_mocap_source("mocap:cmu/16_35.bvh") == tmp_path / "cmu" / "16_35.bvh"
    other = tmp_path / "other"
    other.mkdir()
    assert resolve_mocap_source("mocap:a.bvh", other) == other / "a.bvh"
    assert is_mocap_source("mocap:a.bvh") and not is_mocap_source("builtin:walk")


def test_a_mocap_source_without_a_folder_says_how_to_set_one(monkeypatch):
    monkeypatch.delenv(MOCAP_ENV, raising=False)
    with pytest.raises(MocapUnset, match=MOCAP_ENV):
        resolve_mocap_source("mocap:cmu/16_35.bvh")


@pytest.mark.parametrize("source", ["mocap:", "mocap:/etc/passwd", "mocap:../secret.bvh"])
def test_a_mocap_source_stays_inside_the_folder(tmp_path, monkeypatch, source):
    monkeypatch.setenv(MOCAP_ENV, str(tmp_path))
    with pytest.raises(AvatarsimError, match="RELATIVE/PATH"):
        resolve_mocap_source(source)
