"""The five folders install as subpackages of one import namespace, ``avatarsim.<folder>``
(``avatarsim.sim``, ``avatarsim.scripts``, ...), so that nothing called ``sim`` or
``scripts`` lands at the top of site-packages. The rest of the configuration is in
pyproject.toml; only this mapping is here, because setuptools' static ``packages.find``
cannot put a prefix on the packages it finds."""

from setuptools import find_packages, setup

FOLDERS = ("avatar_models", "render_cams", "synthesis", "sim", "scripts")

setup(
    packages=[f"avatarsim.{p}" for p in find_packages(include=[f"{f}*" for f in FOLDERS])],
    package_dir={f"avatarsim.{f}": f for f in FOLDERS},
)
