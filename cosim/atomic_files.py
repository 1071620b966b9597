"""Atomic file output: write to a temporary file in the destination folder, then rename over the target.

A reader never sees a half-written file, and a failure leaves no file behind.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path
from typing import Iterator

from cosim.errors import InputError


TEMPORARY_NAME_EXTRA = 10  # bytes a temporary sibling's name adds to the target's: "." and mkstemp's 8-character tag and "."
# A run folder is written as a hidden sibling, "." + its name + PARTIAL_TAG + mkdtemp's 8 characters, and renamed
# when it is complete (cosim.pour_run); what a killed run left is found by that tag (cosim.sweep.store).
PARTIAL_TAG = ".partial-"
PARTIAL_NAME_EXTRA = 1 + len(PARTIAL_TAG) + 8  # bytes that sibling's name adds to the run folder's


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; on success it is renamed to ``path``, on error removed."""
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=target.suffix or ".tmp", dir=target.parent)
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        yield tmp_path
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp_path, 0o666 & ~umask)  # mkstemp makes it private; the result gets the usual permissions
        os.replace(tmp_path, target)
    finally:
        if tmp_path.exists():
            tmp_path.unlink()


def check_output_folder(path: str | os.PathLike, field: str, name_extra: int = 0) -> None:
    """Refuse, before a command does any work, an output folder it could not create or write in, with an
    :class:`InputError` naming ``field`` (the option that gave the path), instead of a traceback after the work: each
    name still to be created must fit the file system's name length (``NAME_MAX``; the last one ``name_extra`` bytes
    longer, for a temporary sibling named after it), the whole path ``PATH_MAX``, and the nearest existing folder on
    ``path`` must take a new folder. That last is tried, not read off the permission bits (``os.access`` grants root
    everything, a read-only mount or ``/proc`` included): a hidden folder is made there and removed at once, so a
    refused command leaves nothing behind and an accepted one has created nothing (the outputs create their folders
    as they are written)."""
    target = Path(path)
    existing, missing = target, []
    while not os.path.lexists(existing) and existing != existing.parent:  # os.path: False for a name too long, no error
        missing.append(existing.name)
        existing = existing.parent
    if not os.path.isdir(existing):
        what = "a file" if os.path.exists(existing) else "a broken link"
        raise InputError(f"{field}: {existing} is {what}, not a folder")
    name_max = _path_limit(existing, "PC_NAME_MAX", 255)
    for k, name in enumerate(missing):
        allowed = name_max - (name_extra if k == 0 else 0)
        if len(os.fsencode(name)) > allowed:
            raise InputError(f"{field}: the name {name[:40]!r}... is {len(os.fsencode(name))} bytes long; at most {allowed} "
                             f"fit this file system there")
    path_max = _path_limit(existing, "PC_PATH_MAX", 4096)
    if len(os.fsencode(os.path.abspath(target))) + name_extra >= path_max:
        raise InputError(f"{field}: the path is {len(os.fsencode(os.path.abspath(target)))} bytes long; this file system "
                         f"takes less than {path_max - name_extra} there")
    try:
        os.rmdir(tempfile.mkdtemp(prefix=".cosim-write-check-", dir=existing))
    except OSError as exc:
        raise InputError(f"{field}: cannot write in {existing} ({exc.strerror or exc})") from None


def check_output_file(path: str | os.PathLike, field: str) -> None:
    """:func:`check_output_folder` for a file written through :func:`atomic_path` (an existing file is replaced)."""
    target = Path(path)
    if os.path.isdir(target):  # os.path: False for a name too long, no error
        raise InputError(f"{field}: {target} is a folder, not a file")
    if os.path.exists(target):
        check_output_folder(target.parent, field)
    else:
        check_output_folder(target, field, TEMPORARY_NAME_EXTRA + len(os.fsencode(target.suffix or ".tmp")))


def _path_limit(folder: Path, name: str, default: int) -> int:
    """``os.pathconf(folder, name)``, or ``default`` where the system does not say."""
    try:
        value = os.pathconf(folder, name)
    except (OSError, ValueError, AttributeError):
        return default
    return value if value and value > 0 else default


def write_text_atomic(path: str | os.PathLike, text: str) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(text)
