"""Atomic outputs: a file is written whole or not at all, and a command's outputs all or none.

A writer fills a temporary file beside its destination and renames it into place on
success (:func:`atomic_output`); a command with several outputs checks them all before
writing any and restores them if it fails (:func:`all_or_none`). So a failed or killed
command leaves nothing half-written.
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

from spine_mj.errors import SpineInputError

__all__ = ["all_or_none", "atomic_output", "remove_temporaries", "writable_path"]


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike, *, suffix: str | None = None) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; move it onto ``path`` only on success.

    Whatever goes wrong inside the block (an exception, a kill before the rename), no
    half-written file is left at ``path``: the rename is atomic on POSIX file systems.

    Parameters
    ----------
    path
        Final destination. Its parent directory is created if missing.
    suffix
        Suffix of the temporary file (some writers pick the format from it); defaults to
        the suffix of ``path``.
    """
    dest = writable_path(path)
    fd, tmp_name = tempfile.mkstemp(
        prefix=f".{dest.name}.",
        suffix=suffix if suffix is not None else dest.suffix,
        dir=dest.parent,
    )
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        try:
            yield tmp
        except OSError as exc:  # a writer's error without its file (a full disk): name it
            if exc.filename is not None:
                raise
            raise SpineInputError(f"cannot write {dest}: {exc.strerror or exc}") from None
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; give the usual permissions
        os.replace(tmp, dest)
    finally:
        if tmp.exists():
            tmp.unlink()


#: The temporary files of :func:`atomic_output` (``.NAME.XXXXXXXX.SUFFIX``, mkstemp's 8
#: random characters) and :func:`all_or_none` (``.NAME.PID.keep``).
_TEMPORARY = re.compile(r"^\.(?P<name>.+)\.(?:[a-z0-9_]{8}(?P<suffix>\.[^.]+)?|\d+\.keep)$")


def remove_temporaries(folder: str | os.PathLike) -> list[Path]:
    """Delete, under ``folder`` (recursively), the temporary files that :func:`atomic_output`
    and :func:`all_or_none` leave when their process is killed; a resumed run calls this for
    the run it replaces. Returns the files removed."""
    removed = []
    for path in Path(folder).rglob(".*"):
        m = _TEMPORARY.match(path.name)
        if not (m and path.is_file()):
            continue
        if m["suffix"] is not None and Path(m["name"]).suffix != m["suffix"]:
            continue  # not one of ours: the suffix is the destination's
        path.unlink(missing_ok=True)
        removed.append(path)
    return removed


def _missing_folders(path: Path) -> list[Path]:
    """The folders above ``path`` that do not exist yet."""
    missing = []
    folder = path.parent
    while not folder.exists() and folder != folder.parent:
        missing.append(folder)
        folder = folder.parent
    return missing


def writable_path(path: str | os.PathLike) -> Path:
    """``path`` as a :class:`Path` whose folder exists (created if missing) and takes files.

    Raises
    ------
    SpineInputError
        The folder cannot be made (a parent is a file, no permission) or written to, or
        ``path`` is a folder: named with the system's reason, before any work is done.
    """
    dest = Path(path)
    if dest.is_dir():
        raise SpineInputError(f"cannot write {dest}: it is a folder, expected a file path")
    blocking = next((p for p in dest.parents if p.exists() and not p.is_dir()), None)
    if blocking is not None:
        raise SpineInputError(f"cannot write {dest}: {blocking} is a file, not a folder")
    try:
        dest.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=dest.parent):
            pass
    except OSError as exc:
        raise SpineInputError(f"cannot write {dest}: {exc.strerror or exc}") from None
    return dest


@contextlib.contextmanager
def all_or_none(*paths: str | os.PathLike | None) -> Iterator[None]:
    """Outputs of one command: all of them are written, or none is changed.

    Every path is checked for writability on entry (:func:`writable_path`), so a bad
    second output fails before the first is written. Files that existed are kept aside
    (a hard link) and restored if the block raises; files the block created are removed.
    ``None`` entries are skipped, so optional outputs can be passed as they are. Folders
    made for the outputs are removed again if the block raises.
    """
    new_dirs = {d for p in paths if p is not None for d in _missing_folders(Path(p))}
    dests = [writable_path(p) for p in paths if p is not None]
    backups: dict[Path, Path] = {}
    try:
        for dest in dests:
            if dest.is_file():
                backup = dest.with_name(f".{dest.name}.{os.getpid()}.keep")
                try:
                    os.link(dest, backup)
                except OSError:  # a file system without hard links
                    shutil.copy2(dest, backup)
                backups[dest] = backup
        yield
    except BaseException:
        for dest in dests:
            if dest in backups:
                os.replace(backups.pop(dest), dest)
            elif dest.exists():
                dest.unlink()
        for folder in sorted(new_dirs, key=lambda d: len(d.parts), reverse=True):
            with contextlib.suppress(OSError):  # not empty: something else was put there
                folder.rmdir()
        raise
    finally:
        for backup in backups.values():
            backup.unlink(missing_ok=True)
