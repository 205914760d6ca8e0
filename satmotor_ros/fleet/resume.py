# SPDX-License-Identifier: Apache-2.0
"""
What is already done: a recording's fingerprint and the done-marker written last.

A recording's outputs are complete when ``DIR/<motor>/<recording>/`` holds
:data:`DONE` (written last, atomically), every output file it lists is still there, and
it names the same options and the same input: the same file sizes and modification times,
or, when those moved (a copy, a touch), the same content hash. The stat check costs a
``stat`` per file, so a rerun with nothing to do reads no data; the hash is only computed
where the stat differs, once: :class:`HashCache` keeps it by the new stat for the next run.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path
from typing import Any

DONE = '.fleet-done.json'
"""The done-marker in each recording's output directory."""

_CHUNK = 1 << 20


def _files(path: Path) -> list[Path]:
    if path.is_dir():
        return sorted(p for p in path.rglob('*') if p.is_file())
    return [path]


def stat_of(path: str | Path) -> list[list[Any]]:
    """
    Return the (relative name, size, mtime_ns) of every file of a recording.

    Parameters
    ----------
    path : str or pathlib.Path
        A file or a bag directory, [-]

    Returns
    -------
    list of list
        One ``[name, size, mtime_ns]`` per file, sorted by name.

    """
    base = Path(path)
    out = []
    for file in _files(base):
        st = file.stat()
        name = file.relative_to(base).as_posix() if base.is_dir() else base.name
        out.append([name, st.st_size, st.st_mtime_ns])
    return out


def content_of(path: str | Path) -> str:
    """
    Hash the content of a recording (each file's name and bytes, in name order).

    Parameters
    ----------
    path : str or pathlib.Path
        The recording: a file or a bag directory, [-]

    Returns
    -------
    str
        The BLAKE2b digest, hexadecimal.

    """
    base = Path(path)
    digest = hashlib.blake2b(digest_size=20)
    for file in _files(base):
        name = file.relative_to(base).as_posix() if base.is_dir() else ''
        digest.update(name.encode() + b'\0')
        with file.open('rb') as stream:
            while chunk := stream.read(_CHUNK):
                digest.update(chunk)
        digest.update(b'\0')
    return digest.hexdigest()


HASHES = '.fleet-hashes.json'
"""The fleet's cache of its recordings' content hashes, in DIR."""


class HashCache:
    """
    The content hash of each recording by its files' (size, mtime), kept in DIR.

    A recording touched since its marker (same content, another mtime) is hashed once, by
    the first run that sees it; the runs after find its hash here by its stat and read no
    data. The file keeps the hashes a run asked for (a recording gone is dropped).
    """

    def __init__(self, directory: str | Path) -> None:
        self.path = Path(directory) / HASHES
        found = read_marker(self.path) or {}
        held = found.get('recordings')
        self._held: dict[str, Any] = held if isinstance(held, dict) else {}
        self._asked: dict[str, Any] = {}

    def content(self, path: str | Path) -> str:
        """Return :func:`content_of` a recording, hashed only when its stat is not known."""
        stat = stat_of(path)
        key = str(path)
        entry = self._asked.get(key) or self._held.get(key)  # once a run, then once a stat
        if not (isinstance(entry, dict) and entry.get('stat') == stat
                and isinstance(entry.get('content'), str)):
            entry = {'stat': stat, 'content': content_of(path)}
        self._asked[key] = entry
        return str(entry['content'])

    def save(self) -> None:
        """Write the hashes asked for, whole (a temporary name renamed into place)."""
        if self._asked == self._held or not self.path.parent.is_dir():
            return
        temporary = self.path.with_name(f'{HASHES}.partial-{os.getpid()}')
        temporary.write_text(json.dumps({'recordings': self._asked}, sort_keys=True) + '\n',
                             encoding='utf-8')
        os.replace(temporary, self.path)


def options_key(options: dict[str, Any]) -> str:
    """Hash the options a recording's outputs depend on (JSON with sorted keys)."""
    text = json.dumps(options, sort_keys=True, default=str)
    return hashlib.blake2b(text.encode(), digest_size=20).hexdigest()


def read_marker(path: Path) -> dict[str, Any] | None:
    """Return the JSON mapping a marker file holds, or None (no file, or not a readable one)."""
    try:
        marker = json.loads(path.read_text(encoding='utf-8'))
    except (OSError, ValueError):
        return None
    return marker if isinstance(marker, dict) else None


def read_done(directory: Path) -> dict[str, Any] | None:
    """Return the done-marker of an output directory, or None (none, or unreadable)."""
    return read_marker(directory / DONE)


def is_done(directory: Path, path: str | Path, options: str,
            hashes: HashCache | None = None) -> dict[str, Any] | None:
    """
    Return the done-marker when the outputs are complete for this input and options.

    Parameters
    ----------
    directory : pathlib.Path
        The recording's output directory, [-]
    path : str or pathlib.Path
        The recording, [-]
    options : str
        :func:`options_key` of the options asked now, [-]
    hashes : HashCache, optional
        The fleet's known hashes (a touched recording is not hashed again), [-]

    Returns
    -------
    dict or None
        The marker (its ``result`` is what the run found), or None when it must be redone.

    """
    marker = read_done(directory)
    if marker is None or marker.get('options') != options:
        return None
    outputs = marker.get('outputs', [])
    if not isinstance(outputs, list) or not all((directory / str(name)).is_file()
                                                for name in outputs):
        return None  # an output was deleted: redo the recording
    try:
        if marker.get('stat') == stat_of(path):
            return marker
        content = hashes.content(path) if hashes is not None else content_of(path)
        return marker if marker.get('content') == content else None
    except OSError:
        return None


def write_done(directory: Path, marker: dict[str, Any], only: tuple[str, ...] | None = None) \
        -> None:
    """
    Write the done-marker whole (a temporary name renamed into place), last.

    It lists the output files the directory holds now (``outputs``; not the temporaries an
    interrupted run left; with `only`, those under the entries it names: this run's, not
    another task's or an earlier run's), which :func:`is_done` checks are all still there.
    """
    directory.mkdir(parents=True, exist_ok=True)
    files = (p.relative_to(directory) for p in directory.rglob('*') if p.is_file())
    marker = {**marker, 'outputs': sorted(
        f.as_posix() for f in files if f.name != DONE and (only is None or f.parts[0] in only)
        and not any('.partial-' in part or '.old-' in part for part in f.parts))}
    temporary = directory / f'{DONE}.partial-{os.getpid()}'
    temporary.write_text(json.dumps(marker, indent=1, sort_keys=True) + '\n', encoding='utf-8')
    os.replace(temporary, directory / DONE)


__all__ = ['DONE', 'HASHES', 'HashCache', 'content_of', 'is_done', 'options_key', 'read_done',
           'read_marker', 'stat_of', 'write_done']
