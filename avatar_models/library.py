"""A motion library: an index of the motion files in a folder, labelled by activity, subject,
style and take, with queries and cross-subject / cross-trial splits.

Labels come from the file name, by the first scheme that matches:

- CMU ``SS_TT`` (e.g. ``06_06.amc``): subject ``SS``, take ``TT``, source ``"cmu"``.
- Bandai Namco ``dataset-N_{content}_{style}_{take}``: activity = content, style, take; the
  ``.json`` beside the file (``{"content": i, "style": j}``) and the ``cfg/*_label.txt`` files of
  the dataset, when present, take precedence over the name. Subject unknown (None).
- Free form (e.g. ``walk_fast_subject3_take2.bvh``, ``jog-02.bvh``): the name is split on
  ``_ - . space``; ``subject3``/``subj3``/``s3``/``actor3`` (or ``subject 3``) gives the subject,
  ``take2``/``trial2``/``t2`` or else a trailing number gives the take, the first known activity
  word (:data:`ACTIVITY_WORDS`, with ``-ing`` forms) or else the first word is the activity, and
  the remaining words, joined by ``-``, the style.

Then per-directory annotations override them: a ``CLIPS.md``-style markdown table with a
``clip`` column and ``activity`` / ``subject`` / ``style`` / ``take`` columns (an activity cell
``swimming (breaststroke)`` gives activity ``swimming``, style ``breaststroke``), or an
``index.toml`` / ``index.json`` mapping clip names to tables of those keys.

Subjects are strings with leading zeros dropped for numbers (CMU ``06`` -> ``"6"``); takes are ints.
"""

from __future__ import annotations

import json
import re
import tomllib
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, replace
from pathlib import Path

from avatarsim.avatar_models.errors import AvatarsimError, MotionValueError
from avatarsim.avatar_models.formats import load_motion
from avatarsim.avatar_models.motion import Motion

MOTION_SUFFIXES = (".bvh", ".amc", ".npz")
LABEL_KEYS = ("activity", "subject", "style", "take")
# Activity words recognised in free-form names: the generator's activities, CMU/Bandai contents
# and common mocap verbs.
ACTIVITY_WORDS = frozenset(
    "walk run jog dash sprint jump hop skip box punch kick slash dribble basketball climb ladder "
    "swim wave squat lunge balance dance bow bye byebye guide respond call throw catch sit stand "
    "crawl turn stretch golf soccer football tennis fight raise".split()
)
_CMU = re.compile(r"^(\d+)_(\d+)$")
_BANDAI = re.compile(r"^(dataset-\d+)_([^_]+)_([^_]+)_(\d+)$")
_SUBJECT = re.compile(r"^(?:subject|subj|sub|actor|performer|s|p)(\d+)$")
_SUBJECT_WORDS = ("subject", "subj", "actor", "performer")
_TAKE = re.compile(r"^(?:take|trial|tk|t)(\d+)$")
_TAKE_WORDS = ("take", "trial")


@dataclass(frozen=True)
class Clip:
    """One motion file and its labels (None where unknown)."""

    path: Path
    format: str
    activity: str | None = None
    subject: str | None = None
    style: str | None = None
    take: int | None = None
    source: str | None = None

    @property
    def name(self) -> str:
        return self.path.stem

    def load(self, **options) -> Motion:
        """The clip's motion (:func:`~avatar_models.formats.load_motion`), labels in ``meta``."""
        motion = load_motion(self.path, **options)
        labels = {k: getattr(self, k) for k in (*LABEL_KEYS, "source")}
        return motion.replace(meta={**motion.meta, **labels})


@dataclass(frozen=True)
class Fold:
    """One split: ``test`` holds the clips whose ``by`` label is ``held_out``."""

    by: str
    held_out: str | int
    train: list[Clip]
    test: list[Clip]


def _norm_subject(value: object) -> str | None:
    if value is None or str(value).strip() == "":
        return None
    text = str(value).strip()
    return str(int(text)) if text.isdigit() else text


def _norm_take(value: object) -> int | None:
    if value is None or str(value).strip() == "":
        return None
    try:
        return int(str(value).strip())
    except ValueError:
        raise AvatarsimError(f"take must be an integer, got {value!r}") from None


def _activity_word(word: str) -> str | None:
    """``word`` or its stem if it is a known activity (walking -> walk, running -> run)."""
    if word in ACTIVITY_WORDS:
        return word
    if word.endswith("ing"):
        stem = word[:-3]
        for candidate in (stem, stem + "e", stem[:-1]):  # jog, dance, run (runn-ing)
            if candidate in ACTIVITY_WORDS:
                return candidate
    return None


def parse_free_form(stem: str) -> dict:
    """Labels of a free-form clip name by the heuristic of the module docstring."""
    words = [w for w in re.split(r"[_\-.\s]+", stem.lower()) if w]
    labels: dict = {"activity": None, "subject": None, "style": None, "take": None}
    rest = []
    i = 0
    while i < len(words):
        w = words[i]
        nxt = words[i + 1] if i + 1 < len(words) else ""
        if w in _SUBJECT_WORDS and nxt.isdigit():
            labels["subject"], i = _norm_subject(nxt), i + 2
            continue
        if w in _TAKE_WORDS and nxt.isdigit():
            labels["take"], i = int(nxt), i + 2
            continue
        if m := _SUBJECT.match(w):
            labels["subject"] = _norm_subject(m.group(1))
        elif m := _TAKE.match(w):
            labels["take"] = int(m.group(1))
        else:
            rest.append(w)
        i += 1
    if labels["take"] is None and rest and rest[-1].isdigit():
        labels["take"] = int(rest.pop())
    rest = [w for w in rest if not w.isdigit()]
    known = [k for k, w in enumerate(rest) if _activity_word(w)]
    if rest:
        k = known[0] if known else 0
        labels["activity"] = _activity_word(rest[k]) or rest[k]
        labels["style"] = "-".join(rest[:k] + rest[k + 1 :]) or None
    return labels


def _bandai_labels(path: Path, dataset: str, content: str, style: str) -> tuple[str, str]:
    """Content and style from the ``.json`` beside ``path`` and the dataset's ``cfg/`` labels."""
    annotation = path.with_suffix(".json")
    cfg = next(
        (d / "cfg" for d in path.parents if (d / "cfg" / "content_label.txt").is_file()), None
    )
    if not annotation.is_file() or cfg is None:
        return content, style
    try:
        ids = json.loads(annotation.read_text())
        labels = []
        for kind in ("content", "style"):
            names = (cfg / f"{kind}_label.txt").read_text().split()
            labels.append(names[int(ids[kind])].removeprefix(f"{dataset}_"))
    except (OSError, ValueError, KeyError, IndexError, TypeError):
        return content, style  # an unreadable annotation falls back to the file name
    return labels[0], labels[1]


def parse_clip_name(path: Path) -> Clip:
    """A :class:`Clip` labelled from ``path``'s name (and Bandai annotations beside it)."""
    fmt = path.suffix.lower().lstrip(".")
    if m := _CMU.match(path.stem):
        return Clip(
            path, fmt, subject=_norm_subject(m.group(1)), take=int(m.group(2)), source="cmu"
        )
    if m := _BANDAI.match(path.stem):
        dataset, content, style, take = m.groups()
        content, style = _bandai_labels(path, dataset, content, style)
        return Clip(path, fmt, content, None, style, int(take), source=f"bandai-{dataset}")
    return Clip(path, fmt, **parse_free_form(path.stem))


def _markdown_table(path: Path) -> dict[str, dict]:
    """``{clip: {label: value}}`` from the first markdown table with a ``clip`` column."""
    rows = [
        [c.strip() for c in line.strip().strip("|").split("|")]
        for line in path.read_text().splitlines()
        if line.strip().startswith("|")
    ]
    if not rows:
        return {}
    header = [h.lower() for h in rows[0]]
    if "clip" not in header:
        return {}
    columns = {
        key: next((i for i, h in enumerate(header) if h.startswith(key)), None)
        for key in LABEL_KEYS
    }
    out = {}
    for row in rows[1:]:
        if len(row) != len(header) or set("".join(row)) <= set("-: "):
            continue  # the |---|---| separator or a ragged row
        labels = {k: row[i] for k, i in columns.items() if i is not None and row[i]}
        activity = labels.get("activity", "")
        if m := re.match(r"^(.*?)\s*\((.+)\)$", activity):
            labels["activity"] = m.group(1)
            labels.setdefault("style", m.group(2))
        out[row[header.index("clip")]] = labels
    return out


def _annotations(directory: Path) -> dict[str, dict]:
    """Per-clip label overrides from ``CLIPS.md``, ``index.toml``, ``index.json`` in a folder."""
    out: dict[str, dict] = {}
    if (directory / "CLIPS.md").is_file():
        out.update(_markdown_table(directory / "CLIPS.md"))
    for name, loader in (("index.toml", tomllib.loads), ("index.json", json.loads)):
        if (directory / name).is_file():
            try:
                data = loader((directory / name).read_text())
            except (ValueError, tomllib.TOMLDecodeError) as exc:
                raise AvatarsimError(f"{directory / name}: cannot parse ({exc})") from None
            clips = data.get("clips", data)
            out.update({str(k): dict(v) for k, v in clips.items() if isinstance(v, dict)})
    return out


def _as_set(value: object, norm) -> set | None:
    if value is None:
        return None
    values = value if isinstance(value, list | tuple | set | frozenset) else [value]
    return {norm(v) for v in values}


class MotionLibrary:
    """Clips indexed from a folder. Iterable, sized; see :meth:`query` and :meth:`split`."""

    def __init__(self, clips: Iterable[Clip], root: Path | None = None):
        self.clips = sorted(clips, key=lambda c: str(c.path))
        self.root = root

    @classmethod
    def index(cls, folder: str | Path) -> MotionLibrary:
        """Every ``.bvh`` / ``.amc`` / ``.npz`` under ``folder`` (recursively), labelled."""
        root = Path(folder)
        if not root.is_dir():
            raise AvatarsimError(f"motion library folder {root} does not exist")
        notes: dict[Path, dict[str, dict]] = {}
        clips = []
        for path in root.rglob("*"):
            if path.suffix.lower() not in MOTION_SUFFIXES or not path.is_file():
                continue
            clip = parse_clip_name(path)
            if path.parent not in notes:
                notes[path.parent] = _annotations(path.parent)
            override = notes[path.parent].get(path.stem, {})
            if override:
                labels = {k: override[k] for k in LABEL_KEYS if k in override}
                if "subject" in labels:
                    labels["subject"] = _norm_subject(labels["subject"])
                if "take" in labels:
                    labels["take"] = _norm_take(labels["take"])
                clip = replace(clip, **labels)
            clips.append(clip)
        return cls(clips, root)

    def __len__(self) -> int:
        return len(self.clips)

    def __iter__(self) -> Iterator[Clip]:
        return iter(self.clips)

    def __repr__(self) -> str:
        return f"MotionLibrary({len(self)} clips, {len(self.activities())} activities)"

    def _values(self, key: str) -> list:
        return sorted({getattr(c, key) for c in self.clips if getattr(c, key) is not None}, key=str)

    def activities(self) -> list[str]:
        return self._values("activity")

    def subjects(self) -> list[str]:
        return self._values("subject")

    def styles(self) -> list[str]:
        return self._values("style")

    def query(self, activity=None, subject=None, style=None, take=None, source=None) -> list[Clip]:
        """Clips matching every given label; each may be one value or a list of values."""
        wanted = {
            "activity": _as_set(activity, lambda v: str(v).lower()),
            "subject": _as_set(subject, _norm_subject),
            "style": _as_set(style, lambda v: str(v).lower()),
            "take": _as_set(take, _norm_take),
            "source": _as_set(source, str),
        }

        def fits(clip: Clip) -> bool:
            for key, values in wanted.items():
                value = getattr(clip, key)
                value = value.lower() if key in ("activity", "style") and value else value
                if values is not None and value not in values:
                    return False
            return True

        return [c for c in self.clips if fits(c)]

    def group_by(self, key: str) -> dict:
        """``{label value: [clips]}`` over clips that have the label ``key``."""
        if key not in (*LABEL_KEYS, "source", "format"):
            raise AvatarsimError(f"cannot group by {key!r}; use one of {LABEL_KEYS}")
        groups: dict = {}
        for clip in self.clips:
            value = getattr(clip, key)
            if value is not None:
                groups.setdefault(value, []).append(clip)
        return dict(sorted(groups.items(), key=lambda kv: str(kv[0])))

    def split(self, by: str = "subject") -> Iterator[Fold]:
        """Leave-one-group-out folds: ``by="subject"`` (cross-subject) or ``"take"`` (cross-trial).

        Each fold tests on one subject (take) and trains on all other clips, including those
        without the label. Raises :class:`MotionValueError` with fewer than two groups.
        """
        if by not in ("subject", "take"):
            raise MotionValueError(f"split by 'subject' or 'take', not {by!r}")
        groups = self.group_by(by)
        if len(groups) < 2:
            raise MotionValueError(
                f"a cross-{by} split needs at least 2 {by}s; this library has {len(groups)}"
            )
        for value, test in groups.items():
            held = {id(c) for c in test}
            yield Fold(by, value, [c for c in self.clips if id(c) not in held], test)
