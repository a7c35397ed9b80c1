"""Motion file formats: BVH (read/write), CMU ASF/AMC (read), NPZ (avatarsim's own, read/write).

``load_motion(path)`` picks the reader by extension; ``save_motion(motion, path)`` the writer.
Every reader raises :class:`~avatar_models.errors.MotionFormatError` (with path and line) on
malformed input and returns a ``Motion`` in metres, Z up; ``load_motion`` then refuses a
motion no body could make (:func:`~avatar_models.motion_bounds.check_physical`).
"""

from __future__ import annotations

from pathlib import Path

from avatarsim.avatar_models.errors import MotionFormatError
from avatarsim.avatar_models.motion import Motion
from avatarsim.avatar_models.motion_bounds import check_physical

READABLE = (".bvh", ".amc", ".npz")
WRITABLE = (".bvh", ".npz")


def load_motion(path: str | Path, **options) -> Motion:
    """Read a motion file. ``options`` go to the format's reader (e.g. ``unit=``, ``asf=``).

    Raises:
        MotionFormatError: malformed. MotionValueError: physically absurd values
        (:func:`~avatar_models.motion_bounds.check_physical`: file, frame and channel).
    """
    motion = _read_motion(Path(path), **options)
    kept_rest_frame = options.get("drop_rest_frame") is False  # its step to the take is a jump
    check_physical(motion, path, from_frame=int(kept_rest_frame))
    return motion


def _read_motion(path: Path, **options) -> Motion:
    suffix = path.suffix.lower()
    if path.is_dir():
        raise MotionFormatError("is a directory, not a motion file", path)
    if not path.is_file():
        raise MotionFormatError("no such file", path)
    if suffix == ".bvh":
        from avatarsim.avatar_models.formats.bvh import read_bvh

        return read_bvh(path, **options)
    if suffix == ".amc":
        from avatarsim.avatar_models.formats.asf_amc import read_asf_amc

        return read_asf_amc(path, **options)
    if suffix == ".npz":
        from avatarsim.avatar_models.formats.npz import read_npz

        if options:
            raise MotionFormatError(
                f"NPZ files are always metres, Z up; options {sorted(options)} do not apply", path
            )
        return read_npz(path)
    raise MotionFormatError(
        f"unknown motion format {suffix!r}; readable: {', '.join(READABLE)}", path
    )


def save_motion(motion: Motion, path: str | Path, **options) -> Path:
    """Write ``motion`` to ``path`` (by extension), atomically (temp file then rename).

    A folder that cannot be created or written raises :class:`MotionFormatError`.
    """
    try:
        return _save_motion(motion, Path(path), **options)
    except OSError as exc:
        raise MotionFormatError(f"cannot write: {exc.strerror or exc}", path) from exc


def _save_motion(motion: Motion, path: Path, **options) -> Path:
    suffix = path.suffix.lower()
    if suffix == ".bvh":
        from avatarsim.avatar_models.formats.bvh import write_bvh

        return write_bvh(motion, path, **options)
    if suffix == ".npz":
        from avatarsim.avatar_models.formats.npz import write_npz

        return write_npz(motion, path, **options)
    raise MotionFormatError(f"cannot write {suffix!r}; writable: {', '.join(WRITABLE)}", path)
