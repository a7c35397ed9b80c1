"""Where real motion capture lives on this machine.

An installed avatarsim has no checkout around it, so real mocap (``../shared/mocap`` in the
project's checkout, see its README) is found only where a user says: an explicit folder (a
command's ``--mocap``), else the ``AVATARSIM_MOCAP`` environment variable. No default: a
benchmark or test that wants real clips and finds none says so.

A motion source written ``mocap:cmu/16_35.bvh`` (a scenario's ``motion.source``, any command's
MOTION argument) names a file inside that folder, so shipped scenarios and scripts name real
clips without knowing where a machine keeps them.
"""

from __future__ import annotations

import os
from pathlib import Path

from avatarsim.avatar_models.errors import AvatarsimError

MOCAP_ENV = "AVATARSIM_MOCAP"
MOCAP_PREFIX = "mocap:"


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


class MocapUnset(AvatarsimError):
    """A ``mocap:`` source was named, but no mocap folder is (neither option nor variable)."""


def is_mocap_source(source: str) -> bool:
    """Whether ``source`` names a clip inside the mocap folder (``mocap:RELATIVE/PATH``)."""
    return source.startswith(MOCAP_PREFIX)


def resolve_mocap_source(source: str, explicit: str | Path | None = None) -> Path:
    """The file a ``mocap:RELATIVE/PATH`` source names, inside :func:`mocap_dir`.

    The file itself need not exist (callers decide between skipping and failing).

    Raises:
        MocapUnset: no mocap folder is named.
        MocapNotFound: the folder named is not a directory.
        AvatarsimError: the relative path is empty, absolute or leaves the folder.
    """
    relative = source[len(MOCAP_PREFIX) :]
    if not relative or Path(relative).is_absolute() or ".." in Path(relative).parts:
        raise AvatarsimError(
            f"{source!r}: write {MOCAP_PREFIX}RELATIVE/PATH inside the mocap folder "
            f"(for example {MOCAP_PREFIX}cmu/16_35.bvh)"
        )
    folder = mocap_dir(explicit)
    if folder is None:
        raise MocapUnset(
            f"{source!r} names a real clip, but no mocap folder is set: set {MOCAP_ENV}=DIR, or "
            "pass --mocap DIR where the command has it (DIR holds cmu/ and bandai/, see "
            "../shared/mocap/README.md)"
        )
    return folder / relative
