"""Package re-exports resolved on first use (PEP 562 module ``__getattr__``).

A package ``__init__`` re-exports its public names, as mink's does, so a user imports
``from avatarsim.sim import humanoid_for`` instead of finding the module. Importing them eagerly
would load mujoco, torch or pyrender for every ``avatarsim --help``; resolved on first access,
a name costs nothing until it is used, and ``dir()`` and ``__all__`` still list it.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable


def lazy_exports(
    package: str, exports: dict[str, str]
) -> tuple[Callable[[str], object], Callable[[], list[str]]]:
    """``__getattr__`` and ``__dir__`` for ``package`` re-exporting ``exports`` (public name
    -> module path relative to ``package``, e.g. ``{"humanoid_for": ".humanoid"}``)."""

    def getattr_(name: str) -> object:
        module = exports.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        return getattr(importlib.import_module(module, package), name)

    def dir_() -> list[str]:
        return sorted({*vars(sys.modules[package]), *exports})

    return getattr_, dir_
