"""An import-linter contract (and the same check for pytest): no module uses another module's
private names.

A private name starts with one underscore (``_x``; dunders such as ``__version__`` are not
private). Across modules of the root packages, three uses are refused:

- ``from a.b import _c``;
- ``import a._b`` / ``from a._b import c`` (a private module);
- ``m._c`` where ``m`` is a name bound by importing one of our modules or a name from one
  (``import a.b as m``; ``from a import b``, then ``b._c``).

Attribute use on other objects (``self._x``, ``obj._x``) cannot be told apart from outside
without types and is not checked. Registered in ``pyproject.toml`` as the contract type
``private_names``; ``tests/test_private_imports.py`` runs the same check.
"""

from __future__ import annotations

import ast
import importlib.util
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


@dataclass(frozen=True)
class PrivateUse:
    """One use of another module's private name: ``path:line: what``."""

    path: str
    line: int
    what: str

    def __str__(self) -> str:
        return f"{self.path}:{self.line}: {self.what}"

    @property
    def key(self) -> str:
        """``path: what``, without the line: how an allow-list names a known use."""
        return f"{self.path}: {self.what}"


def _private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def _ours(module: str, packages: tuple[str, ...]) -> bool:
    """Whether dotted ``module`` is one of ``packages`` (dotted names) or inside one."""
    return any(module == p or module.startswith(p + ".") for p in packages)


def private_uses_in(path: Path, packages: Iterable[str], root: Path = ROOT) -> Iterator[PrivateUse]:
    """The private names of our ``packages`` (dotted names) that the file at ``path`` uses."""
    packages = tuple(packages)
    rel = str(path.relative_to(root))
    tree = ast.parse(path.read_text(), filename=rel)
    ours: set[str] = set()  # local names bound to our modules or to names imported from them
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                parts = alias.name.split(".")
                if not _ours(alias.name, packages):
                    continue
                if any(map(_private, parts)):
                    yield PrivateUse(rel, node.lineno, f"import {alias.name}")
                ours.add(alias.asname or parts[0])
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            parts = node.module.split(".")
            if not _ours(node.module, packages):
                continue
            if any(map(_private, parts)):
                yield PrivateUse(rel, node.lineno, f"from {node.module} import ...")
            for alias in node.names:
                if _private(alias.name):
                    yield PrivateUse(rel, node.lineno, f"from {node.module} import {alias.name}")
                ours.add(alias.asname or alias.name)
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and _private(node.attr):
            base = node.value
            while isinstance(base, ast.Attribute):
                base = base.value
            if isinstance(base, ast.Name) and base.id in ours:
                yield PrivateUse(rel, node.lineno, f"{ast.unparse(node)}")


def private_uses(packages: Iterable[str], extra_folders: Iterable[str] = ()) -> list[PrivateUse]:
    """Every use of another module's private name in ``packages`` (and ``extra_folders``, e.g.
    ``tests``, as users of them)."""
    packages = tuple(packages)
    folders = []
    for package in packages:
        spec = importlib.util.find_spec(package)
        folders += [Path(p) for p in spec.submodule_search_locations]
    folders += [ROOT / f for f in extra_folders]
    return [
        use
        for folder in folders
        for path in sorted(folder.rglob("*.py"))
        for use in private_uses_in(path, packages)
    ]


try:
    from importlinter import Contract, ContractCheck, fields, output
except ImportError:  # pytest without import-linter: only the check functions are needed
    pass
else:

    class PrivateNamesContract(Contract):
        """``type = "private_names"``: no module of ``packages`` uses another's private name
        (see the module docstring); ``allowed`` lists known uses to be removed (``path: what``);
        an entry that no longer matches is reported as a warning."""

        type_name = "private_names"
        packages = fields.ListField(subfield=fields.StringField())
        allowed = fields.ListField(subfield=fields.StringField(), required=False)

        def check(self, graph, verbose: bool) -> ContractCheck:
            allowed = set(self.allowed or ())
            found = private_uses(self.packages)
            uses = [str(u) for u in found if u.key not in allowed]
            stale = sorted(allowed - {u.key for u in found})
            warnings = [f"allowed private use no longer found: {key}" for key in stale]
            return ContractCheck(kept=not uses, metadata={"uses": uses}, warnings=warnings)

        def render_broken_contract(self, check: ContractCheck) -> None:
            for use in check.metadata["uses"]:
                output.print_error(use)
            output.new_line()
            output.print(
                "Make the name public (with a docstring) or keep its use inside its module."
            )
