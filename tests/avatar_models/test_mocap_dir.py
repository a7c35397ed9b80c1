"""Real mocap is found where the user says (option, then ``$AVATARSIM_MOCAP``), never by
where the code lives; a folder named but absent is a user error."""

from __future__ import annotations

import pytest

from avatarsim.avatar_models import AvatarsimError
from avatarsim.avatar_models.mocap_dir import MOCAP_ENV, mocap_dir


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
