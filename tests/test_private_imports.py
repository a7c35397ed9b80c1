"""No module uses another module's private name (``_x``): the check of tests/private_names.py
(also an import-linter contract in pyproject.toml) over the packages and the tests."""

from pathlib import Path

from tests.private_names import PrivateUse, private_uses, private_uses_in

PACKAGES = tuple(
    f"avatarsim.{p}" for p in ("avatar_models", "render_cams", "synthesis", "sim", "scripts")
)


def test_no_module_or_test_uses_another_modules_private_name():
    found = private_uses(PACKAGES, extra_folders=("tests",))
    assert not found, "private names used across modules:\n" + "\n".join(map(str, found))


def test_the_check_finds_each_kind_of_private_use(tmp_path):
    source = tmp_path / "user.py"
    source.write_text(
        "import avatarsim.sim._hidden\n"
        "from avatarsim.sim.tracking import _up, Tracker\n"
        "from avatarsim.avatar_models import quat as q\n"
        "import numpy as np\n"
        "q._normalise(np._private)\n"
        "Tracker._com_jacobian\n"
        "self_made = object()\n"
        "self_made._fine\n"
    )
    uses = sorted(private_uses_in(source, PACKAGES, root=tmp_path), key=lambda u: u.line)
    assert [(u.line, u.what) for u in uses] == [
        (1, "import avatarsim.sim._hidden"),
        (2, "from avatarsim.sim.tracking import _up"),
        (5, "q._normalise"),
        (6, "Tracker._com_jacobian"),
    ]
    assert uses[0] == PrivateUse("user.py", 1, "import avatarsim.sim._hidden")
    assert not list(private_uses_in(Path(__file__), PACKAGES))  # this file is clean
