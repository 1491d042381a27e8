"""ASAM MDF logs (``.mf4``, ``.mdf``; asammdf, extra ``logs``): channels with their own time stamps and units."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ...errors import InputError
from .base import Source


class MdfSource(Source):
    """An ASAM MDF log: channels by name, each with its own time stamps (its group's master) and unit.

    A name that is in several data groups is refused unless it is given as ``GROUP/NAME``, GROUP the data
    group's index (as asammdf's ``MDF.get(name, group=...)`` counts them) or its acquisition name.
    """

    def __init__(self, path: Path, label: str):
        try:
            from asammdf import MDF
        except ImportError:
            raise InputError(f"{label}: MDF logs need asammdf: pip install 'ehm[logs]'.") from None
        self.mdf, failure = _open_mdf(MDF, path)
        if failure is not None:
            raise InputError(f"{label}: not a readable MDF file ({failure}).")
        masters = self.mdf.masters_db
        names = [n for n, places in self.mdf.channels_db.items()
                 if any(masters.get(g) != i for g, i in places)]  # the data channels, not the time stamps
        super().__init__(label=label, names=names, kind="channels", per_channel_time=True)
        self._masters = {}
        self.first_comment = self._comment()

    def _comment(self) -> str:
        """The file's or its first channel group's comment, as plain text (it describes the log); asammdf's
        default group comment "Python" says nothing about the log and is passed over."""
        for text in [getattr(self.mdf.header, "comment", "")] + [g.channel_group.comment for g in self.mdf.groups]:
            plain = re.sub(r"<[^>]*>", " ", str(text or "")).strip()
            if plain and plain != "Python":
                return " ".join(plain.split())
        return ""

    def _places(self, name: str) -> list:
        """(group, index) of every data channel of that name."""
        masters = self.mdf.masters_db
        return [(g, i) for g, i in self.mdf.channels_db.get(name, ()) if masters.get(g) != i]

    def _group_name(self, group: int) -> str:
        return str(getattr(self.mdf.groups[group].channel_group, "acq_name", "") or "")

    def _split(self, name: str):
        """``GROUP/NAME`` -> (group index, NAME) when NAME is in that group; else None."""
        head, sep, rest = name.partition("/")
        if not sep or not rest:
            return None
        groups = [g for g, _ in self._places(rest)]
        if head.strip().isdigit():
            chosen = [int(head)] if int(head) in groups else []
        else:
            chosen = [g for g in groups if self._group_name(g) == head.strip()]
        return (chosen[0], rest) if len(chosen) == 1 else None

    def has(self, name: str) -> bool:
        return name in self.names or self._split(name) is not None

    def check_unique(self, key: str, name: str) -> None:
        """Refuse a bare name that is in several data groups, naming them and the GROUP/NAME form."""
        places = self._places(name) if name in self.names else []
        if len(places) > 1:
            groups = [f"{g}" + (f" ({self._group_name(g)})" if self._group_name(g) else "") for g, _ in places]
            example = f"{key}={places[-1][0]}/{name}"
            raise InputError(f"{self.label}: channel {key} ({name!r}) is in data groups {', '.join(groups[:-1])} "
                             f"and {groups[-1]}; name one as GROUP/NAME, GROUP its index or name, e.g. --channel "
                             f"{example} (Python: channels={{{key!r}: '{example.split('=', 1)[1]}'}}).")

    def _where(self, name: str):
        if name not in self.names:  # GROUP/NAME
            group, rest = self._split(name)
            return next((g, i) for g, i in self._places(rest) if g == group), rest
        return self._places(name)[0], name

    def values(self, name: str) -> np.ndarray:
        (group, index), name = self._where(name)
        samples, _ = self.mdf.get(name, group, index, samples_only=True)
        return samples

    def time_of(self, name: str) -> np.ndarray:
        (group, _), _ = self._where(name)
        if group not in self._masters:
            self._masters[group] = np.asarray(self.mdf.get_master(group), dtype=float)
        return self._masters[group]

    def unit_of(self, name: str) -> str:
        (group, index), name = self._where(name)
        return (self.mdf.get_channel_unit(name, group, index) or "").strip()

    def close(self) -> None:
        self.mdf.close()


def _open_mdf(MDF, path: Path):
    """(asammdf's MDF of the file, None), or (None, the first line of why it cannot be read).

    asammdf's MDF4 object of a file it fails to read complains from its destructor (a traceback on stderr,
    after ehm's sentence); that object is let go and collected here, its destructor's complaint dropped."""
    import gc
    import sys

    failure = None
    hook = sys.unraisablehook

    def quiet(unraisable):
        where = getattr(unraisable.object, "__module__", "") or ""
        if not where.startswith("asammdf"):
            hook(unraisable)

    sys.unraisablehook = quiet
    try:
        try:
            return MDF(str(path)), None
        except Exception as exc:  # noqa: BLE001 - asammdf raises several kinds for a file that is not MDF
            failure = (str(exc).splitlines() or [type(exc).__name__])[0]
        gc.collect()  # the half-built object goes now, while its destructor's complaint is dropped
    finally:
        sys.unraisablehook = hook
    return None, failure
