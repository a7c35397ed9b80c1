"""The pyrender private names that render_cams.pyrender_patch relies on exist in the installed
pyrender; a change is reported by name and version, not as wrong pixels."""

import pyrender
import pytest

from avatarsim.render_cams import pyrender_patch
from avatarsim.render_cams.pyrender_patch import (
    PyrenderPatchError,
    check_pyrender,
    missing_private_names,
)


def test_the_installed_pyrender_has_every_private_name_the_patch_uses():
    check_pyrender()  # raises PyrenderPatchError naming the version and the names


@pytest.fixture
def fresh_check():
    missing_private_names.cache_clear()
    yield
    missing_private_names.cache_clear()


def test_a_removed_method_is_named_with_the_pyrender_version(monkeypatch, fresh_check):
    monkeypatch.delattr(pyrender.Renderer, "_read_main_framebuffer")
    with pytest.raises(PyrenderPatchError) as info:
        check_pyrender()
    message = str(info.value)
    assert "Renderer._read_main_framebuffer" in message
    assert f"pyrender {pyrender_patch.pyrender_version()}" in message


def test_a_changed_signature_and_a_missing_attribute_are_reported(monkeypatch, fresh_check):
    monkeypatch.setattr(pyrender.Renderer, "_configure_main_framebuffer", lambda self, extra: 0)
    monkeypatch.setattr(pyrender_patch, "RENDERER_ATTRIBUTES", ("_no_such_buffer",))
    missing = missing_private_names()
    assert any(m.startswith("Renderer._configure_main_framebuffer (parameters") for m in missing)
    assert "Renderer._no_such_buffer (attribute gone)" in missing
