"""Every package's public API: each name in ``__all__`` resolves (lazily or not) to the object
its defining module holds, none hides a submodule of the same name, and the lazy ones stay
unloaded until used, so the CLI starts without torch."""

from __future__ import annotations

import importlib
import pkgutil
import subprocess
import sys
import types

import pytest

PACKAGES = [
    "avatarsim.avatar_models",
    "avatarsim.render_cams",
    "avatarsim.sim",
    "avatarsim.synthesis",
    "avatarsim.scripts",
    "avatarsim.scripts.dataset",
]


@pytest.mark.parametrize("name", PACKAGES)
def test_every_public_name_resolves_to_its_defining_modules_object(name):
    package = importlib.import_module(name)
    submodules = {m.name for m in pkgutil.iter_modules(package.__path__)}
    assert package.__all__, name
    for public in package.__all__:
        value = getattr(package, public)
        assert not isinstance(value, types.ModuleType), f"{name}.{public} is a module"
        assert public not in submodules, f"{name}.{public} shadows the submodule {public}"
        home = getattr(value, "__module__", None)
        if home is not None:  # functions and classes: the same object as in their module
            assert home.startswith(name), f"{name}.{public} comes from {home}"
            assert getattr(sys.modules[home], public, value) is value
    assert set(package.__all__) <= set(dir(package))


def test_an_unknown_name_is_an_attribute_error_naming_the_package():
    import avatarsim.sim

    with pytest.raises(AttributeError, match="avatarsim.sim.*humanoid_fro"):
        avatarsim.sim.humanoid_fro  # noqa: B018


def test_the_cli_imports_without_loading_torch_or_the_methods():
    code = (
        "import sys, avatarsim.scripts.cli, avatarsim.sim, avatarsim.synthesis;"
        "print(sorted(m for m in ('torch', 'avatarsim.synthesis.methods', 'mediapipe')"
        " if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
