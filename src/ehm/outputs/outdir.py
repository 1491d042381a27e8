"""Output folders written as one unit, and output locations checked before any work starts.

A command that writes a folder (``ehm simulate``, ``assess``, ``demo``, ``study``; ``RunResult.write``) puts
every file into a hidden staging folder beside the target, ``.NAME.partial-PID-XXXX``, and only when all of
them are written swaps it into place: in one step where the system can exchange two directories (Linux,
``renameat2`` with ``RENAME_EXCHANGE``), otherwise by two renames with SIGINT and SIGTERM held back in
between.  The earlier folder is then removed.  So a folder always holds the files of one run: a new run's
files never sit beside an earlier run's (an old figure, an old ``poses.npz``), and a failure or an interrupt
at any moment leaves the earlier folder as it was (or no folder, and no parent folders the command made).

A folder is replaced whole, so ehm replaces only a folder it wrote itself: every folder it writes carries a
manifest, ``ehm.files.MANIFEST_NAME``, naming the command, the ehm version and every file it wrote with its size and
modification time.  An existing folder is replaced only when it is empty, or when it carries that manifest and
holds nothing but the files listed there, each of its listed size and time (a file added or changed since is the
user's), and neither it nor anything in it is read-only.  Names and extensions are never taken as evidence.
Anything else is refused, before the run starts, with one sentence, and again just before the swap (a file added
while the run was going keeps the folder; the new run is then left beside it).  A batch study's folder is added
to rather than replaced (``added_folder``), under the same rule; its manifest is kept in memory while a study runs and
written at most about once a second, and a run record written since names the folder's id, so that a study killed
meanwhile (SIGKILL, a power cut) resumes with it.  A study folder of an earlier ehm, without a manifest, is refused
with a sentence saying so.

No file joins a manifest silently: only a file that belongs to the folder is listed (``record_in_manifest``:
a batch study's records and tables, an animation drawn into its own run folder).  A single file of any other
command is refused inside a folder of ehm's (``check_output_file``), and one written there from Python is not
listed, so the next run refuses the folder rather than deleting it; a run also refuses an output folder that holds
one of its own input files.

Staging folders left by a process that no longer runs (killed with SIGKILL, a power cut) are removed the next time
the same target is written, recognised by the staging manifest ehm writes into them first (naming the folder, the
process and the machine), never by their names.
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import json
import math
import os
import secrets
import shutil
import signal
import socket
import stat
import sys
import tempfile
import threading
import time
from importlib import metadata
from pathlib import Path

from ..errors import EhmWarning, InputError, warn
from ..files import MANIFEST_NAME, fsync_directory, manifest_or_why, read_manifest, write_json_atomic

#: Its format, written into it: a later ehm can tell what it reads.
MANIFEST_FORMAT = 1
#: A folder being added to writes its manifest at most this often (s), and when the command ends.
FLUSH_INTERVAL_S = 1.0
#: The field of a JSON file that ehm wrote into a folder being added to: the folder's id (its manifest's
#: ``folder_id``), by which the file is known as ehm's before the manifest lists it.
OWN_MARK = "ehm_folder_id"
#: A file larger than this is not read to see whether it is ehm's (a run record is a few kB).
_MARKED_MAX_BYTES = 16 << 20
_STAGING = ".{name}.partial-{pid}-"
_OLD = ".{name}.old-{pid}-"

_command: str | None = None


def set_command(command: str | None) -> None:
    """Name the command that writes folders from now on (the command-line interface sets ``ehm ...``)."""
    global _command
    _command = command


def _ehm_version() -> str:
    try:
        return metadata.version("ehm")
    except metadata.PackageNotFoundError:
        return "unknown"


def _manifest_data(what: str, state: str, files: dict, mtimes: dict) -> dict:
    return {"written_by": "ehm", "format": MANIFEST_FORMAT, "state": state, "ehm_version": _ehm_version(),
            "command": _command or f"ehm (Python): {what}",
            "written_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()), "files": files, "mtime_ns": mtimes}


def _write_manifest(folder: Path, what: str, state: str) -> None:
    """Write the manifest of ``folder``, a folder written as one unit: the files ehm wrote there (sub-folders
    included) with their sizes in bytes and modification times in ns (a file edited in place keeps its size, not its
    time).

    ``state`` "complete": a finished folder, listing every file under it.  ``state`` "staging": a staging folder,
    named in its manifest with the process and the machine writing it; that is what :func:`remove_stale` goes by,
    never the folder's name."""
    files, mtimes = {}, {}
    if state == "complete":
        for p in sorted(folder.rglob("*")):
            rel = p.relative_to(folder).as_posix()
            if rel != MANIFEST_NAME and p.is_file() and not p.is_symlink():
                st = p.stat()
                files[rel], mtimes[rel] = st.st_size, st.st_mtime_ns
    data = _manifest_data(what, state, files, mtimes)
    if state == "staging":
        data["staging"] = {"folder": folder.name, "pid": os.getpid(), "host": socket.gethostname()}
    with open(folder / MANIFEST_NAME, "w", encoding="utf-8") as fh:
        json.dump(data, fh, indent=1)
        fh.write("\n")
        fh.flush()
        os.fsync(fh.fileno())


def record_in_manifest(path: Path | str, folder: Path | str) -> None:
    """List a file just written into ``folder``, a finished folder of ehm's, in its manifest (and the manifest it
    changed in the folder above when that is ehm's too, a demo's run folders, and so on up).

    Only for a file that belongs to the folder: a batch study's records and tables, an animation of a run drawn
    into that run's folder.  A file written into a folder of ehm's by anything else is never listed (ehm refuses
    to write one there, ``check_output_file``), so the next run refuses the folder instead of deleting it.
    In a folder being added to in this process (:func:`added_folder`) it goes into the manifest kept in memory,
    which is written at once."""
    listing = _OPEN.get(os.path.realpath(folder))
    if listing is not None:  # a folder being added to: its manifest is in memory, written now
        listing.add(Path(path), Path(folder), now=True)
        return
    changed, folder = [Path(path)], Path(folder)
    while True:
        data = read_manifest(folder)
        if data is None or data.get("state") != "complete":
            return
        mtimes = data.setdefault("mtime_ns", {})
        for c in changed:
            rel = c.relative_to(folder).as_posix()
            st = c.stat()
            data["files"][rel], mtimes[rel] = st.st_size, st.st_mtime_ns
        write_json_atomic(folder / MANIFEST_NAME, data)
        changed.append(folder / MANIFEST_NAME)
        if folder.parent == folder:
            return
        folder = folder.parent


def foreign_entry(folder: Path) -> str | None:
    """Why ``folder`` is not a folder that ehm may replace, as the words after its name; None when it may be.

    It may be replaced when it is empty, or when it carries an ehm manifest and holds nothing but the files listed
    there, each of its listed size and modification time (sub-folders included)."""
    entries = sorted(folder.iterdir())
    if not entries:
        return None
    data, why = manifest_or_why(folder)
    if why is not None:
        return (f"has a manifest, {MANIFEST_NAME}, that is {why}, so ehm cannot tell the files it wrote there from "
                "any others")
    if data is None:
        return f"holds {entries[0].name}, which ehm did not write (the folder has no ehm manifest, {MANIFEST_NAME})"
    if data.get("state") != "complete":
        return "is the staging folder of an unfinished ehm run"
    for rel, p, why in _unmatched(folder, data):
        if not _written_since_listing(p, data):
            return f"holds {rel}, {why}"
    return None


def _unmatched(folder: Path, data: dict):
    """The files under ``folder`` that its manifest ``data`` does not list as they are: (relative name, path, why:
    the words after the name)."""
    listed, mtimes = data["files"], data.get("mtime_ns", {})
    for p in sorted(folder.rglob("*")):
        rel = p.relative_to(folder).as_posix()
        if rel == MANIFEST_NAME or (p.is_dir() and not p.is_symlink()):
            continue
        if p.is_symlink() or not p.is_file() or rel not in listed:
            yield rel, p, "which ehm did not write"
            continue
        st = p.stat()
        if st.st_size != listed[rel] or (rel in mtimes and st.st_mtime_ns != mtimes[rel]):
            yield rel, p, "which was changed after ehm wrote it"


def _written_since_listing(p: Path, data: dict) -> bool:
    """Whether ``p``, a file its folder's manifest ``data`` does not list as it is, is one that ehm wrote there
    after the manifest was last written, by a command that ended without writing it again (killed, a power cut).

    Only a folder that is added to (:func:`added_folder`) leaves files unlisted for a while, and only files that say
    so themselves: JSON objects that name the folder's own id (``OWN_MARK``, :func:`write_owned_json`), and only
    while the manifest says the command adding to it did not end (``"open"``).  A file of any other content, or one
    found after the command closed the manifest, is not ehm's (names are never taken as evidence)."""
    folder_id = data.get("folder_id")
    if not data.get("open") or not isinstance(folder_id, str) or p.is_symlink() or not p.is_file():
        return False
    try:
        if p.stat().st_size > _MARKED_MAX_BYTES:
            return False
        content = json.loads(p.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError):
        return False
    return isinstance(content, dict) and content.get(OWN_MARK) == folder_id


def _read_only_entry(folder: Path) -> Path | None:
    """The folder itself, or the first thing in it, that is read-only (its owner may not write it), or None.

    Judged by the mode bits as well as by the system's answer: a user who takes away the write permission means
    "keep this", also where the permission would not stop the writer (root)."""
    for p in [folder, *sorted(folder.rglob("*"))]:
        if p.is_symlink():
            continue
        if not p.stat().st_mode & stat.S_IWUSR or not os.access(p, os.W_OK):
            return p
    return None


def _managing_folder(path: Path) -> Path | None:
    """The nearest folder above ``path`` that is a finished folder of ehm's (it carries a complete manifest)."""
    for p in Path(os.path.abspath(path)).parents:
        data = read_manifest(p)
        if data is not None and data.get("state") == "complete":
            return p
    return None


def _check_not_inside_ehms_folder(path: Path, what: str) -> None:
    """Refuse to write ``path`` into a folder that ehm manages: the next run of that folder would replace it whole
    (and a file of that folder's manifest may be replaced only by ehm's own run)."""
    owner = _managing_folder(path)
    if owner is None:
        return
    where = owner if path.is_absolute() else Path(os.path.relpath(owner))
    raise InputError(f"{path}: {where} is an output folder of ehm's, which holds only the files ehm wrote for it "
                     f"(its {MANIFEST_NAME} lists them); write the {what} outside it, e.g. {where.parent / path.name}.")


def resolved_path(path: Path | str, what: str = "output") -> Path:
    """``path`` with its symbolic links followed (:meth:`pathlib.Path.resolve`), or one sentence when they cannot
    be (a link loop, whose RuntimeError or OSError would otherwise end the command in a traceback)."""
    try:
        try:  # Python 3.13 no longer raises on a loop unless strict: ask strictly, a missing path is no loop
            Path(path).resolve(strict=True)
        except OSError as exc:
            if exc.errno == errno.ELOOP:
                raise
        return Path(path).resolve()
    except (RuntimeError, OSError) as exc:
        why = "a symbolic link loop" if isinstance(exc, RuntimeError) or exc.errno == errno.ELOOP else (
            exc.strerror or str(exc))
        raise InputError(f"{path}: the {what} path cannot be followed ({why}); remove the link or give another "
                         "output path.") from None


def _nearest_existing(path: Path) -> Path:
    p = path
    while not p.exists() and p != p.parent:
        p = p.parent
    return p


def _check_creatable(path: Path, what: str) -> None:
    """The folder that would hold ``path`` exists as a writable folder, or can be made."""
    base = _nearest_existing(path.parent)
    if not base.is_dir():
        raise InputError(f"{path}: cannot write the {what} there: {base} is a file, not a folder.")
    if not os.access(base, os.W_OK | os.X_OK):
        raise InputError(f"{path}: cannot write the {what} there: the folder {base} is not writable.")


def check_output_folder(path: Path | str, what: str = "output", inputs=(), added_to: bool = False) -> Path:
    """Make sure a run's output folder can be written and replaced whole; before any work starts.

    The folder may be absent, empty or an earlier folder of ehm's that holds nothing else (see the module
    docstring), not read-only and not inside another folder of ehm's.  None of the run's ``inputs`` (the files
    it reads) may lie in it.  ``added_to``: the folder is added to rather than replaced (a batch study's).
    Returns the path.  Raises InputError with one sentence otherwise (a file in the way, a folder holding files
    ehm did not write, a read-only folder, an input in it, the current folder, no write permission).
    """
    path = Path(path)
    resolved = resolved_path(path, what + " folder")
    if path.exists() and not path.is_dir():
        raise InputError(f"{path} is a file; give a folder for the {what}.")
    here = Path.cwd().resolve()
    if resolved == here or resolved in here.parents:
        raise InputError(f"{path}: the {what} folder would hold the current folder; give a new folder, "
                         "e.g. --out runs/first (ehm replaces its output folder whole).")
    _check_not_inside_ehms_folder(path, what + " folder")
    for given in inputs:
        if resolved in Path(given).resolve().parents:
            raise InputError(f"{path}: the {what} folder holds {given}, which this command reads; give another "
                             f"folder for the {what}" + ("." if added_to else " (ehm replaces it whole)."))
    if path.is_dir():
        _check_ehms_and_writable(path, what, "adds only to" if added_to else "replaces only")
    _check_creatable(path, what + " folder")
    return path


def _check_ehms_and_writable(path: Path, what: str, verb: str) -> None:
    try:
        why = foreign_entry(path)
        locked = _read_only_entry(path)
    except OSError as exc:
        raise InputError(f"{path}: cannot read the {what} folder ({exc.strerror or exc}).") from None
    if why and verb == "adds only to" and _earlier_study_folder(path):
        raise InputError(f"{path} is a study folder of an earlier ehm, written before study folders carried a manifest "
                         f"({MANIFEST_NAME}), so it cannot be resumed: ehm cannot tell the files it wrote there from "
                         f"any others; run the study into a new folder, e.g. {path.parent / (path.name + '-new')} "
                         "(the earlier results stay where they are).")
    if why:
        raise InputError(f"{path} {why}; give a new or empty folder for the {what}: ehm {verb} a folder "
                         "that it wrote and that holds nothing else.")
    if locked is not None:
        which = "is read-only" if locked == path else f"holds {locked.relative_to(path).as_posix()}, which is read-only"
        raise InputError(f"{path} {which}, so ehm leaves it as it is; give another folder for the {what}, or make "
                         f"it writable first (chmod -R u+w {path}).")


def _earlier_study_folder(path: Path) -> bool:
    """Whether ``path``, a folder without a manifest, is a batch study's folder written by an ehm from before study
    folders carried one: by content, a run record in its ``runs`` folder (a JSON object with the run's inputs and
    run id, its outputs and its error), not by the names alone."""
    if manifest_or_why(path) != (None, None) or not (path / "runs").is_dir():
        return False
    for p in sorted((path / "runs").glob("*.json"))[:3]:
        try:
            rec = json.loads(p.read_text(encoding="utf-8")) if p.stat().st_size <= _MARKED_MAX_BYTES else None
        except (OSError, UnicodeDecodeError, ValueError):
            continue
        if isinstance(rec, dict) and isinstance(rec.get("inputs"), dict) and "run_id" in rec["inputs"] \
                and {"outputs", "error"} <= set(rec):
            return True
    return False


def check_output_file(path: Path | str, what: str = "output file", part_of: Path | str | None = None) -> Path:
    """Make sure a single output file can be written (before any work starts); returns the path.

    It may not go into a folder that ehm manages (its files listed in a manifest), unless it belongs to it:
    ``part_of`` is the folder of ehm's it is written for (an animation of a run, drawn into that run's folder)."""
    path = Path(path)
    resolved_path(path, what)
    if path.is_dir():
        raise InputError(f"{path} is a folder; give a file name for the {what}.")
    if part_of is None or path.parent.resolve() != Path(part_of).resolve():
        _check_not_inside_ehms_folder(path, what)
    if path.exists() and not os.access(path.parent, os.W_OK | os.X_OK):
        raise InputError(f"{path}: cannot write the {what}: the folder {path.parent} is not writable.")
    _check_creatable(path, what)
    return path


def check_file_destination(out: Path | str, suffix: str, kind: str) -> Path:
    """Make sure a single file ending in ``suffix`` can be put at ``out``, before the (long) work that makes it:
    the name ends in ``suffix``, it is not a folder, its folder exists (made if missing) and takes a new file
    (probed with a temporary file).  ``kind`` names the file in the sentence, e.g. ``"an FMU"``.  Used by both
    FMU exports (:mod:`ehm.interfaces.fmu`, :mod:`ehm.interfaces.fmu_native`).  Returns the path."""
    out = Path(out)
    if out.suffix.lower() != suffix:
        raise InputError(f"{out}: {kind} file name must end in {suffix}.")
    resolved_path(out, "FMU")
    _check_not_inside_ehms_folder(out, "FMU")
    if out.is_dir():
        raise InputError(f"{out}: is a folder; give a file name ending in {suffix}.")
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"{out}: cannot create the folder {out.parent} ({exc.strerror or exc}).") from None
    try:  # fail before the build when the folder takes no new file
        fd, probe = tempfile.mkstemp(dir=out.parent, prefix=f".{out.name}.", suffix=".tmp")
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise InputError(f"{out}: cannot write a file in the folder {out.parent} ({exc.strerror or exc}).") from None
    return out


@contextlib.contextmanager
def signals_held():
    """Hold SIGINT, SIGTERM and SIGHUP back while inside: they are noted and handled on leaving (by the handlers that
    were in place), so that what happens inside is not cut short.  Only the main thread handles signals; in
    other threads this does nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    pending: list[int] = []
    held = (signal.SIGINT, signal.SIGTERM) + ((signal.SIGHUP,) if hasattr(signal, "SIGHUP") else ())
    previous = {s: signal.signal(s, lambda signum, frame: pending.append(signum)) for s in held}
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler if handler is not None else signal.SIG_DFL)
        for s in pending:
            handler = previous[s]
            if callable(handler):
                handler(s, None)
            elif handler in (signal.SIG_DFL, None):
                os.kill(os.getpid(), s)


_RENAME_EXCHANGE = 2
_AT_FDCWD = -100


def _exchange(a: Path, b: Path) -> bool:
    """Swap two directory entries in one step (Linux renameat2); False where the system cannot."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        fn = ctypes.CDLL(None, use_errno=True).renameat2
    except (OSError, AttributeError):
        return False
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    fn.restype = ctypes.c_int
    if fn(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE) == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP, errno.ENOTSUP):
        return False  # this file system cannot exchange: two renames instead
    raise OSError(err, os.strerror(err), str(b))


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def remove_stale(target: Path) -> None:
    """Remove staging folders of ``target`` left by processes that no longer run.

    A folder is removed only by what ehm wrote into it first: its staging manifest, which names the folder itself,
    the process that made it (one that no longer runs) and this machine (a process of another machine sharing the
    folder is not judged by this one's process numbers).  A folder that merely has such a name is kept, whatever
    it holds."""
    parent = target.parent
    if not parent.is_dir():
        return
    for pattern in (_STAGING, _OLD):
        prefix = pattern.format(name=target.name, pid="").removesuffix("-")
        for entry in parent.glob(glob_escape(prefix) + "*"):
            if not entry.is_symlink() and entry.is_dir() and _stale_staging(entry):
                _remove_tree(entry)


def _stale_staging(folder: Path) -> bool:
    """Whether ``folder`` is ehm's staging folder of a process of this machine that no longer runs."""
    data = read_manifest(folder)
    mark = data.get("staging") if data is not None and data.get("state") == "staging" else None
    if not isinstance(mark, dict) or mark.get("folder") != folder.name or mark.get("host") != socket.gethostname():
        return False
    pid = mark.get("pid")
    return isinstance(pid, int) and pid != os.getpid() and not _alive(pid)


def _remove_tree(folder: Path) -> None:
    """Remove a folder of ehm's (an earlier run's, once replaced; a stale staging folder), also where a folder in
    it is not writable; what cannot be removed is named in a warning, never left without a word."""
    def writable_and_again(func, path, exc_info):
        with contextlib.suppress(OSError):
            os.chmod(os.path.dirname(path), stat.S_IRWXU)
            func(path)

    shutil.rmtree(folder, onerror=writable_and_again)
    if os.path.lexists(folder):
        warn(f"{folder}: could not remove this hidden folder of an earlier run; delete it yourself.",
             EhmWarning, stacklevel=2)


def glob_escape(text: str) -> str:
    """A literal text for Path.glob."""
    return "".join(f"[{c}]" if c in "*?[" else c for c in text)




def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


class RunFolder:
    """Write a folder as one unit: ``with RunFolder(path) as tmp:`` write into ``tmp``; on leaving without an
    exception ``tmp`` replaces ``path`` (see the module docstring); on an exception (an interrupt included)
    ``tmp`` and any parent folders made for it are removed and ``path`` stays as it was.

    Nested use (a run folder inside a demo folder) works: the inner unit is committed into the outer staging
    folder.
    """

    def __init__(self, target: Path | str, what: str = "output"):
        self.target = Path(target)
        if self.target.is_symlink():  # replace the folder the link points at; the link stays
            self.target = resolved_path(self.target, what)
        self.what = what
        self.staging: Path | None = None
        self._made: list[Path] = []

    def __enter__(self) -> Path:
        check_output_folder(self.target, self.what)
        parent = self.target.parent
        missing = []
        p = parent
        while not p.exists():
            missing.append(p)
            p = p.parent
        try:
            for d in reversed(missing):
                d.mkdir()
                self._made.append(d)
            remove_stale(self.target)
            self.staging = Path(tempfile.mkdtemp(prefix=_STAGING.format(name=self.target.name, pid=os.getpid()),
                                                 dir=parent))
            _write_manifest(self.staging, self.what, "staging")
        except BaseException as exc:  # also Ctrl-C, SIGTERM or SIGHUP meanwhile: no __exit__ would remove it
            self._discard()
            self._remove_made()
            if not isinstance(exc, OSError):
                raise
            raise InputError(f"{self.target}: cannot create the {self.what} folder ({exc.strerror or exc}).") from None
        return self.staging

    def __exit__(self, exc_type, exc, tb) -> bool:
        if exc_type is None:
            try:
                self._commit()
            except OSError as exc2:
                self._discard()
                raise InputError(f"{self.target}: cannot put the {self.what} folder in place "
                                 f"({exc2.strerror or exc2}).") from None
        else:
            staging = self.staging
            self._discard()
            if isinstance(exc, InputError) and staging is not None and str(staging) in str(exc):
                # a sentence about a file in the hidden staging folder names the folder the user asked for
                raise InputError(str(exc).replace(str(staging), str(self.target))) from None
        return False

    def _commit(self) -> None:
        staging, target = self.staging, self.target
        _write_manifest(staging, self.what, "complete")
        mode = stat.S_IMODE(target.stat().st_mode) if target.is_dir() else 0o777 & ~_umask()
        os.chmod(staging, mode)
        with signals_held():
            self._keep_if_foreign()
            old = None
            if target.exists():
                if _exchange(staging, target):
                    old = staging  # now holds the earlier folder: marked as staging, to be removed
                    with contextlib.suppress(OSError):  # (the mark only lets a later run finish the removal)
                        _write_manifest(old, self.what, "staging")
                else:
                    old = Path(tempfile.mkdtemp(prefix=_OLD.format(name=target.name, pid=os.getpid()),
                                                dir=target.parent))
                    _write_manifest(old, self.what, "staging")
                    os.rename(target, old / target.name)
                    os.rename(staging, target)
            else:
                os.rename(staging, target)
            fsync_directory(target.parent)
            self.staging = None
            if old is not None:
                _remove_tree(old)

    def _keep_if_foreign(self) -> None:
        """Just before the swap: if someone put files into the target while the run went on, keep the target as
        it is and leave the new folder beside it, under a name that says so."""
        target = self.target
        why = foreign_entry(target) if target.is_dir() else ("is not a folder" if target.exists() else None)
        if why is None:
            return
        kept = Path(tempfile.mkdtemp(prefix=f"{target.name}.new-", dir=target.parent))
        os.rename(self.staging, kept / target.name)
        self.staging = None
        raise InputError(f"{target} {why} (added while the run went on), so it was left as it is; the new "
                         f"{self.what} is in {kept / target.name}.")

    def _discard(self) -> None:
        with signals_held():
            if self.staging is not None:
                shutil.rmtree(self.staging, ignore_errors=True)
                self.staging = None
            self._remove_made()

    def _remove_made(self) -> None:
        for d in reversed(self._made):
            try:
                d.rmdir()
            except OSError:
                break
        self._made = []


class _Listing:
    """The manifest of a folder being added to (:func:`added_folder`), kept in memory: a file ehm writes there is
    listed at once, the manifest written at most every ``FLUSH_INTERVAL_S`` (or at once when asked), and closed
    (``"open": false``) when the command ends."""

    def __init__(self, path: Path, what: str):
        data = read_manifest(path) or {"files": {}}
        files, mtimes = dict(data["files"]), dict(data.get("mtime_ns", {}))
        for rel, p, _ in _unmatched(path, data):  # left unlisted by a command that was killed: listed now
            if _written_since_listing(p, data):
                st = p.stat()
                files[rel], mtimes[rel] = st.st_size, st.st_mtime_ns
        self.path = path
        self.data = _manifest_data(what, "complete", files, mtimes)
        self.data["folder_id"] = data.get("folder_id") if isinstance(data.get("folder_id"), str) \
            else secrets.token_hex(8)
        self.flushed = -math.inf
        self.flush()

    def add(self, file: Path, folder: Path, now: bool) -> None:
        rel = file.relative_to(folder).as_posix()
        st = file.stat()
        self.data["files"][rel], self.data["mtime_ns"][rel] = st.st_size, st.st_mtime_ns
        if now or time.monotonic() - self.flushed >= FLUSH_INTERVAL_S:
            self.flush()

    def flush(self, close: bool = False) -> None:
        """Write the manifest (whole or not at all), with Ctrl-C and SIGTERM held back meanwhile."""
        with signals_held():
            self.data["open"] = not close
            write_json_atomic(self.path / MANIFEST_NAME, self.data)
            self.flushed = time.monotonic()


#: The folders being added to in this process (their real paths) and their manifests in memory.
_OPEN: dict[str, _Listing] = {}


@contextlib.contextmanager
def added_folder(path: Path | str, what: str = "results"):
    """A folder that is added to over several commands (a batch study's results), under the same rule as a run's
    folder: it must be absent, empty, or ehm's holding nothing but the files its manifest lists (checked here
    too); it gets that manifest (the command and ehm version now adding to it), and every file ehm writes into it
    is listed with :func:`write_owned` or :func:`write_owned_json`.

    While inside, the manifest is kept in memory and written at most about once a second
    (``FLUSH_INTERVAL_S``; a rewrite per file grew with the square of their number: 43 s for 4000), and once more on
    leaving, also on an error, Ctrl-C or SIGTERM.  A command killed in between (SIGKILL, a power cut) leaves files
    unlisted: those that :func:`write_owned_json` wrote name the folder's id and are listed by the next command;
    anything else unlisted is refused as before.  If the command fails or is interrupted while the folder it made
    holds nothing but its manifest and empty folders, the folder (and the parent folders made for it) is
    removed."""
    path = Path(path)
    with folder_lock(path, what):
        yield from _added_folder(path, what)


def _added_folder(path: Path, what: str):
    check_output_folder(path, what, added_to=True)
    existed = path.exists()
    made = []
    p = path
    while not p.exists():
        made.append(p)
        p = p.parent
    try:
        path.mkdir(parents=True, exist_ok=True)
        listing = _Listing(path, what)
    except OSError as exc:
        raise InputError(f"{path}: cannot create the {what} folder ({exc.strerror or exc}).") from None
    key = os.path.realpath(path)
    _OPEN[key] = listing
    ended = False
    try:
        with _closed_on_sigterm(listing):
            yield path
        ended = True
    finally:
        _OPEN.pop(key, None)
        with signals_held():
            try:
                listing.flush(close=True)
            except (OSError, InputError):
                if ended:  # else the error under way is the one to tell; the next command lists what is marked
                    raise
            if not ended and not existed:
                _remove_if_nothing_written(path, made)


#: The lock file of a folder being added to, beside it (so that it is neither in the folder's listing nor needs the
#: folder to exist): ``.<name>.ehm-lock``, holding who took it.
_LOCK = ".{name}.ehm-lock"
_HELD: dict[str, int] = {}  #: the folders this process holds locked (real path -> depth: one process may nest)


@contextlib.contextmanager
def folder_lock(path: Path | str, what: str = "results"):
    """Hold ``path`` for this process while inside: a second process (another ``ehm batch`` into the same folder)
    is refused in one sentence naming the process that holds it, instead of both writing and the second's table
    replacing the first's.  The lock is an advisory ``flock`` on ``.<name>.ehm-lock`` beside the folder: the system
    releases it when its process ends however it ends, so a lock left by a dead process (SIGKILL, a power cut) is
    no lock (its file is taken over); the file is removed on leaving.  Re-entrant within one process; where the
    system has no ``flock`` (Windows), nothing is locked."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - Windows
        yield
        return
    path = Path(path)
    key = os.path.realpath(path)
    if key in _HELD:
        _HELD[key] += 1
        try:
            yield
        finally:
            _HELD[key] -= 1
        return
    lock = Path(key).parent / _LOCK.format(name=Path(key).name)
    fd = _take_lock(fcntl, lock, path, what)
    _HELD[key] = 1
    try:
        yield
    finally:
        _HELD.pop(key, None)
        with contextlib.suppress(OSError):
            lock.unlink()
        os.close(fd)


def _take_lock(fcntl, lock: Path, path: Path, what: str) -> int:
    """The descriptor of ``lock``, opened and locked by this process (a file unlinked by its previous holder between
    our opening and locking it is opened again), or an :class:`InputError` naming the holder."""
    for _ in range(10):
        try:
            fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            raise InputError(f"{path}: cannot lock the {what} folder ({lock}: {exc.strerror or exc}); give a "
                             "folder in a writable place (--out, out= in Python).") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            holder = b""
            with contextlib.suppress(OSError):
                holder = os.pread(fd, 4096, 0)
            os.close(fd)
            who = holder.decode("utf-8", "replace").strip() or "another process"
            raise InputError(f"{path} is being written by another ehm command ({who}); wait for it to end or give "
                             "another folder (--out, out= in Python): two studies into one folder would replace "
                             "each other's table.") from None
        try:
            same = os.fstat(fd).st_ino == os.stat(lock).st_ino
        except OSError:
            same = False
        if same:
            os.ftruncate(fd, 0)
            os.pwrite(fd, (f"process {os.getpid()} on {socket.gethostname()}, since "
                           f"{time.strftime('%Y-%m-%d %H:%M:%S')}: {_command or 'ehm from Python'}").encode(), 0)
            return fd
        os.close(fd)  # its holder removed it meanwhile: take the new one
    raise InputError(f"{path}: cannot lock the {what} folder (its lock file keeps changing); try again.")


@contextlib.contextmanager
def _closed_on_sigterm(listing: _Listing):
    """While inside, SIGTERM left to its default (ending the process at once: ehm used from Python) first writes
    the folder's manifest, closed, and then ends the process as before.  A handler of the program's own (the
    command line raises an exception, so :func:`added_folder` closes the manifest on its way out) is kept."""
    if threading.current_thread() is not threading.main_thread() \
            or signal.getsignal(signal.SIGTERM) not in (signal.SIG_DFL, None):
        yield
        return

    def close_then_end(signum, frame):
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        with contextlib.suppress(OSError, InputError):
            listing.flush(close=True)
        os.kill(os.getpid(), signal.SIGTERM)

    signal.signal(signal.SIGTERM, close_then_end)
    try:
        yield
    finally:
        if signal.getsignal(signal.SIGTERM) is close_then_end:
            signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _remove_if_nothing_written(path: Path, made: list[Path]) -> None:
    written = any(q.is_file() and q.name != MANIFEST_NAME for q in path.rglob("*"))
    if written or (read_manifest(path) or {}).get("files"):
        return
    with contextlib.suppress(OSError):
        (path / MANIFEST_NAME).unlink()
    for d in sorted((q for q in path.rglob("*") if q.is_dir()), key=lambda q: -len(q.parts)):
        with contextlib.suppress(OSError):
            d.rmdir()
    for d in made:
        try:
            d.rmdir()
        except OSError:
            break


def write_owned(path: Path | str, write, folder: Path | str) -> None:
    """Write a file of ``folder`` (a folder of ehm's that is added to, ``added_folder``) and list it in the
    folder's manifest at once, with Ctrl-C and SIGTERM held back in between (so that the two happen together).
    ``write()`` writes ``path`` (atomically, :mod:`ehm.files`)."""
    with signals_held():
        write()
        record_in_manifest(path, folder)


def write_owned_json(path: Path | str, obj: dict, folder: Path | str) -> None:
    """Write the JSON object ``obj`` as a file of ``folder``, a folder being added to (:func:`added_folder`; a batch
    study's run records), atomically, with the folder's id in it (``OWN_MARK``), and list it in the manifest kept in
    memory, which is written within about a second (``FLUSH_INTERVAL_S``): so a file whose listing a killed command
    did not write is still known as ehm's, by what it says, to the next command.  Outside ``added_folder`` it is
    written and listed at once (:func:`write_owned`), without the id."""
    path, folder = Path(path), Path(folder)
    listing = _OPEN.get(os.path.realpath(folder))
    if listing is None:
        write_owned(path, lambda: write_json_atomic(path, obj), folder)
        return
    with signals_held():
        write_json_atomic(path, {**obj, OWN_MARK: listing.data["folder_id"]})
        listing.add(path, folder, now=False)
