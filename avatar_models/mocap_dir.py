"""Where real motion capture lives on this machine.

An installed avatarsim has no checkout around it, so real mocap (``../shared/mocap`` in the
project's checkout, see its README) is found only where a user says: an explicit folder (a
command's ``--mocap``), else the ``AVATARSIM_MOCAP`` environment variable. No default: a
benchmark or test that wants real clips and finds none says so.
"""

from __future__ import annotations

import os
from pathlib import Path

from avatarsim.avatar_models.errors import AvatarsimError

MOCAP_ENV = "AVATARSIM_MOCAP"


class MocapNotFound(AvatarsimError):
    """A mocap folder was named (option or :data:`MOCAP_ENV`) but is not a folder."""


def mocap_dir(explicit: str | Path | None = None) -> Path | None:
    """The real-mocap folder: ``explicit`` if given, else ``$AVATARSIM_MOCAP``, else None.

    Raises:
        MocapNotFound: the folder named is not a directory.
    """
    named, source = (
        (explicit, "--mocap")
        if explicit is not None
        else (
            os.environ.get(MOCAP_ENV) or None,
            f"${MOCAP_ENV}",
        )
    )
    if named is None:
        return None
    path = Path(named).expanduser()
    if not path.is_dir():
        raise MocapNotFound(
            f"{source} names {str(path)!r}, which is not a folder: point it at the mocap "
            "folder (the one holding cmu/ and bandai/, see ../shared/mocap/README.md)"
        )
    return path
