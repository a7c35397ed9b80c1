"""NPZ: avatarsim's own lossless motion format (numpy ``.npz``, no pickles).

Arrays: ``names (J,)`` str, ``parents (J,)``, ``offsets (J, 3)``, ``is_site (J,)``,
``root_pos (T, 3)``, ``local_rot (T, J, 4)`` wxyz, ``fps ()``, ``version ()``, and
``skeleton_json`` (skeleton name and DOF limits) and ``meta_json`` as JSON strings.
Everything is stored in float64, so write -> read is exact.
"""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import numpy as np

from avatarsim.avatar_models.errors import MotionFormatError, MotionValueError
from avatarsim.avatar_models.fileio import atomic_file
from avatarsim.avatar_models.motion import Motion
from avatarsim.avatar_models.skeleton import Skeleton

FORMAT_VERSION = 1
_KEYS = ("version", "names", "parents", "offsets", "is_site", "fps", "root_pos", "local_rot")


def write_npz(motion: Motion, path: str | Path) -> Path:
    """Write ``motion`` to ``path`` atomically (temp file, then ``os.replace``)."""
    path = Path(path)
    sk = motion.skeleton
    skeleton_json = {
        "name": sk.name,
        "limits": {j: {a: list(v) for a, v in ax.items()} for j, ax in sk.limits.items()},
    }
    arrays = {
        "version": np.array(FORMAT_VERSION),
        "names": np.array(sk.names, dtype=str),
        "parents": sk.parents,
        "offsets": sk.offsets,
        "is_site": sk.is_site,
        "fps": np.array(motion.fps),
        "root_pos": motion.root_pos,
        "local_rot": motion.local_rot,
        "skeleton_json": np.array(json.dumps(skeleton_json)),
        "meta_json": np.array(json.dumps(motion.meta, default=str)),
    }
    with atomic_file(path) as fh:
        np.savez_compressed(fh, **arrays)
    return path


def read_npz(path: str | Path) -> Motion:
    """Read a motion written by :func:`write_npz`; malformed files raise MotionFormatError."""
    path = Path(path)
    try:
        with np.load(path, allow_pickle=False) as data:
            missing = [k for k in (*_KEYS, "skeleton_json", "meta_json") if k not in data]
            if missing:
                raise MotionFormatError(f"not an avatarsim motion NPZ (missing {missing})", path)
            arrays = {k: data[k] for k in data.files}
        version = int(arrays["version"])
        if version != FORMAT_VERSION:
            raise MotionFormatError(f"unsupported NPZ format version {version}", path)
        extra = json.loads(str(arrays["skeleton_json"]))
        meta = json.loads(str(arrays["meta_json"]))
        for key, value in (("skeleton_json", extra), ("meta_json", meta)):
            if not isinstance(value, dict):
                raise MotionFormatError(
                    f"{key} must be a JSON object, got a {type(value).__name__}", path
                )
        limits = {
            j: {a: (float(lo), float(hi)) for a, (lo, hi) in ax.items()}
            for j, ax in extra.get("limits", {}).items()
        }
        skeleton = Skeleton(
            tuple(str(n) for n in arrays["names"]),
            arrays["parents"],
            arrays["offsets"],
            arrays["is_site"],
            limits,
            str(extra.get("name", "")),
        )
        return Motion(skeleton, float(arrays["fps"]), arrays["root_pos"], arrays["local_rot"], meta)
    except MotionFormatError:
        raise
    except OSError as exc:
        raise MotionFormatError(f"cannot read: {exc}", path) from None
    except (
        ValueError,
        TypeError,
        KeyError,
        AttributeError,
        EOFError,
        zipfile.BadZipFile,
        json.JSONDecodeError,
        MotionValueError,
    ) as exc:
        raise MotionFormatError(
            f"malformed motion NPZ ({type(exc).__name__}: {exc})", path
        ) from None
