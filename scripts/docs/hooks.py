"""mkdocs hook: one API page per package, listing what its ``__all__`` exports.

Most public names are re-exported lazily (PEP 562, ``avatar_models.lazy_exports``), which a
static reader such as griffe cannot follow from the ``__init__``; so each page points
mkdocstrings at the module that defines the name.
"""

from __future__ import annotations

import importlib
import inspect
import re
import sys

from mkdocs.structure.files import File

PACKAGES = [
    "avatarsim.avatar_models",
    "avatarsim.render_cams",
    "avatarsim.synthesis",
    "avatarsim.sim",
    "avatarsim.scripts",
    "avatarsim.scripts.dataset",
]


def _home(package: str, name: str) -> str:
    """The dotted path of the module that defines ``package``'s public ``name``."""
    value = getattr(importlib.import_module(package), name)
    module = getattr(value, "__module__", None)
    if module and module.startswith(package) and not inspect.ismodule(value):
        return module
    # A constant: the loaded submodule that assigns it at top level.
    for dotted, loaded in sorted(sys.modules.items()):
        if dotted.startswith(package) and vars(loaded).get(name) is value:
            if re.search(rf"^{name}\b[^=\n]*=", inspect.getsource(loaded), re.M):
                return dotted
    raise LookupError(f"no module under {package} defines {name}")


def page(package: str) -> str:
    """The markdown of ``package``'s API page."""
    names = importlib.import_module(package).__all__
    parts = [f"# {package}", f"::: {package}\n    options:\n      members: false"]
    parts += [f"::: {_home(package, n)}.{n}\n    options:\n      heading_level: 2" for n in names]
    return "\n\n".join(parts) + "\n"


def on_files(files, config):
    for package in PACKAGES:
        path = f"api/{package.removeprefix('avatarsim.')}.md"
        files.append(File.generated(config, path, content=page(package)))
    return files
