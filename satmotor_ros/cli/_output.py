# SPDX-License-Identifier: Apache-2.0
"""
Outputs that replace nothing they were not made for, and appear whole or not at all.

Every file and directory a subcommand writes goes through :func:`output_file` or
:func:`output_dir`. The output is first written under a hidden temporary name
beside its target and renamed into place only when complete, so an interrupted
run (SIGINT, a crash, a full disk) leaves the previous result intact and nothing
that looks complete. An existing target is replaced only when it is an earlier
output of the same subcommand (a directory with a :data:`MARKER` naming it, a
file the subcommand's own check recognises), an empty directory, or with
``--force``; an output is never one of the command's inputs.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
import json
import os
from pathlib import Path
import re
import shutil
import signal
import sys
import threading

from satmotor_ros.cli._common import CliError

MARKER = '.satmotor-output.json'
"""File in every output directory naming the subcommand that wrote it."""

COMMITTED: list[Path] = []
"""Each output renamed into place by this process, in order (what an interrupt leaves)."""


def add_out_dir(parser: argparse.ArgumentParser, writer: str = 'this command',
                default: str | None = None) -> None:
    """
    Add ``--out DIR``, the directory :func:`output_dir` writes, and ``--force``.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The subcommand's parser, [-]
    writer : str
        Who wrote an --out that may be replaced without --force, for the help, [-]
    default : str, optional
        The directory when --out is not given; --out is required without one, [-]

    """
    where = f' (default {default})' if default is not None else ''
    parser.add_argument('--out', required=default is None, default=default, metavar='DIR',
                        help=f'output directory{where}, written whole or not at all; an '
                             f'existing one is replaced only if {writer} wrote it')
    parser.add_argument('--force', action='store_true',
                        help=f'replace an existing --out that {writer} did not write')


_HELD = {signal.SIGINT, signal.SIGTERM}


def _temporary(target: Path) -> Path:
    return target.with_name(f'.{target.name}.partial-{os.getpid()}')


_PARTIAL = re.compile(r'\.(?P<name>.+)\.partial-(?P<pid>[0-9]{1,10})')
_ASIDE = re.compile(r'\.(?P<name>.+)\.old-(?P<pid>[0-9]{1,10})-[0-9a-f]{8}')


def _gone(pid: int) -> bool:
    """Whether no process has the id `pid` (one of another user's is there)."""
    if pid == os.getpid():
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except OSError:  # EPERM: alive; anything else: do not guess
        return False
    return False


def clean_stale(directory: Path) -> list[Path]:
    """
    Tidy what runs killed outright (kill -9, a power cut) left in `directory`.

    Only names this module makes are touched, and only when the process named in them is
    gone: a temporary output ``.NAME.partial-PID`` is removed; an output renamed aside at
    commit, ``.NAME.old-PID-HEX``, is put back if NAME is free again (it may be the user's),
    and left where it is otherwise.

    Parameters
    ----------
    directory : pathlib.Path
        Where an output is about to be written, [-]

    Returns
    -------
    list of pathlib.Path
        What was put back under its own name.

    """
    restored: list[Path] = []
    try:
        entries = list(directory.iterdir()) if directory.is_dir() else []
    except OSError:
        return restored
    for entry in entries:
        partial, aside = _PARTIAL.fullmatch(entry.name), _ASIDE.fullmatch(entry.name)
        found = partial or aside
        if found is None or not _gone(int(found['pid'])):
            continue
        if partial is not None:
            _remove(entry)
            continue
        home = entry.with_name(found['name'])
        if not (home.exists() or home.is_symlink()):
            try:
                os.rename(entry, home)
            except OSError:
                continue
            restored.append(home)
    return restored


def check_target(option: str, target: Path, inputs: Sequence[str | Path], force: bool,
                 ours: Callable[[Path], bool], command: str) -> None:
    """
    Refuse a target that is an input, or that exists and is not an earlier output of ours.

    Parameters
    ----------
    option : str
        The option that named the target, for the message (``'--out'``), [-]
    target : pathlib.Path
        File or directory to write, [-]
    inputs : sequence of path
        What the command reads, [-]
    force : bool
        Replace an existing target whatever it is (never an input), [-]
    ours : callable
        Whether an existing target is an earlier output of this subcommand, [-]
    command : str
        The subcommand, for the message, [-]

    Raises
    ------
    CliError
        One line naming the option, the path and what to do.

    """
    resolved = resolve(option, target)
    for item in inputs:
        source = _resolve_or_none(Path(item))
        if source is None:
            continue  # a loop: reading it is one line naming its option
        if resolved == source or source.is_relative_to(resolved) \
                or resolved.is_relative_to(source):
            raise CliError(f'{option} {str(target)!r}: is or contains the input {str(item)!r}; '
                           'choose another path')
    if (target.exists() or target.is_symlink()) and not force and not ours(target) \
            and not _empty_dir(target):
        raise CliError(f'{option} {str(target)!r} exists and is not an earlier output of '
                       f'satmotor {command}; choose a new path or pass --force to replace it')
    _probe(option, target)


def resolve(option: str, path: Path) -> Path:
    """
    Return `path` made absolute with its symbolic links followed; a loop is one line.

    Parameters
    ----------
    option : str
        The option that named it, for the message, [-]
    path : pathlib.Path
        The path as typed, [-]

    Returns
    -------
    pathlib.Path
        The resolved path (the part that does not exist kept as given).

    Raises
    ------
    CliError
        If its symbolic links form a loop (or cannot be read).

    """
    resolved = _resolve_or_none(path)
    if resolved is None:
        raise CliError(f'{option} {str(path)!r}: its symbolic links form a loop (or cannot be '
                       'followed); choose another path')
    return resolved


def _resolve_or_none(path: Path) -> Path | None:
    try:
        return path.resolve()
    except (RuntimeError, OSError):  # RuntimeError('Symlink loop ...') before Python 3.13
        return None


def _probe(option: str, target: Path) -> None:
    """Refuse a target whose directory takes no file, before any work is done for it."""
    if not target.parent.is_dir():
        return  # made when the output is written; an error then is still one line
    probe = _temporary(target)
    blocked = _block_interrupts()  # a signal between making and removing it left it behind
    try:
        probe.open('x').close()
    except FileExistsError:
        return
    except OSError as err:
        raise CliError(f'{option} {str(target)!r}: cannot write there ({err.strerror})') \
            from None
    else:
        probe.unlink(missing_ok=True)
    finally:
        _unblock_interrupts(blocked)


def _empty_dir(path: Path) -> bool:
    return path.is_dir() and not path.is_symlink() and next(path.iterdir(), None) is None


def _files(directory: Path) -> list[str]:
    """Return every file under `directory` but the marker, as sorted relative names."""
    return sorted(p.relative_to(directory).as_posix() for p in directory.rglob('*')
                  if not p.is_dir() and p.name != MARKER)


def write_marker(directory: Path, command: str) -> None:
    """Name `command` and every file it wrote in `directory`'s :data:`MARKER`."""
    (directory / MARKER).write_text(
        json.dumps({'command': command, 'files': _files(directory)}) + '\n', encoding='utf-8')


def written_by(command: str) -> Callable[[Path], bool]:
    """
    Return the check that a directory is an earlier output of `command` and nothing more.

    Its marker must name `command`, and the directory may hold only the files the marker
    lists (some may be gone): a file a user put beside them makes it theirs. A marker
    without a list (written before the list was kept) is taken at its word.
    """
    def ours(path: Path) -> bool:
        try:
            marker = json.loads((path / MARKER).read_text(encoding='utf-8'))
        except (OSError, ValueError):
            return False
        if not (isinstance(marker, dict) and marker.get('command') == command):
            return False
        listed = marker.get('files')
        return listed is None or (isinstance(listed, list)
                                  and set(_files(path)) <= {str(f) for f in listed})
    return ours


def _commit(temporary: Path, target: Path, option: str, command: str, force: bool,
            ours: Callable[[Path], bool]) -> None:
    """
    Move `temporary` onto `target`, checking again what is there now, never over the check.

    Whatever holds `target` at this moment is first renamed aside under a name of this
    process (atomic), so the check of it is the check of what is replaced. What is not ours
    is put back and the run refused; the new output is installed with no-replace semantics
    (a directory is never renamed over a non-empty one, a file is linked), so a target made
    after the check is never replaced either.
    """
    refused = (f'{option} {str(target)!r} was made during the run and is not an earlier '
               f'output of satmotor {command}; it is left as it was; choose a new path or pass '
               '--force to replace it')
    blocked = _block_interrupts()
    try:
        aside = target.with_name(f'.{target.name}.old-{os.getpid()}-{os.urandom(4).hex()}')
        old: Path | None = aside
        try:
            os.rename(target, aside)
        except FileNotFoundError:
            old = None
        if old is not None and not (force or ours(old) or _empty_dir(old)):
            _put_back(old, target, refused)
            raise CliError(refused)
        try:
            _install(temporary, target)
        except OSError:
            if old is not None:
                _put_back(old, target, refused)
            raise CliError(refused) from None
        COMMITTED.append(target)
        if old is not None:
            _remove(old)
    finally:
        _unblock_interrupts(blocked)


def _install(temporary: Path, target: Path) -> None:
    """Rename `temporary` to `target` only if nothing (or an empty directory) is there."""
    if temporary.is_dir():
        os.rename(temporary, target)  # fails on a file and on a non-empty directory
        return
    try:
        os.link(temporary, target)  # fails on anything there, unlike rename
    except FileExistsError:
        raise
    except OSError:  # a file system without hard links
        if target.exists() or target.is_symlink():
            raise FileExistsError(target) from None
        os.rename(temporary, target)
        return
    os.unlink(temporary)


def _put_back(old: Path, target: Path, refused: str) -> None:
    """Return what was renamed aside to `target`; if something took the name, say where."""
    try:
        if old.is_dir() and not old.is_symlink():
            os.rename(old, target)
        else:
            os.link(old, target, follow_symlinks=False)
            os.unlink(old)
    except OSError:
        raise CliError(f'{refused}; what was there before is now {str(old)!r}') from None


def _remove(old: Path) -> None:
    """Remove a replaced output: a link itself, never what it points to."""
    if old.is_dir() and not old.is_symlink():
        shutil.rmtree(old, ignore_errors=True)
    else:
        old.unlink(missing_ok=True)


def _tidy(target: Path) -> None:
    """Clean what killed runs left beside `target`; say what was put back (one line each)."""
    for home in clean_stale(target.parent):
        print(f'satmotor: note: {str(home)!r} was left renamed aside by a run that was killed; '
              'put back', file=sys.stderr)


def _prepare(option: str, out: str | Path, command: str, ours: Callable[[Path], bool],
             inputs: Sequence[str | Path], force: bool) -> tuple[Path, Path]:
    """Tidy beside `out`, refuse it if it may not be replaced; return it and its temporary."""
    target = Path(out)
    _tidy(target)
    check_target(option, target, inputs, force, ours, command)
    target.parent.mkdir(parents=True, exist_ok=True)
    return target, _temporary(target)


def _block_interrupts() -> bool:
    """Hold SIGINT and SIGTERM while an output is being swapped (delivered right after)."""
    if threading.current_thread() is not threading.main_thread():
        return False
    signal.pthread_sigmask(signal.SIG_BLOCK, _HELD)
    return True


def _unblock_interrupts(blocked: bool) -> None:
    if blocked:
        signal.pthread_sigmask(signal.SIG_UNBLOCK, _HELD)


@contextmanager
def output_dir(option: str, out: str | Path, command: str, inputs: Sequence[str | Path] = (),
               force: bool = False) -> Iterator[Path]:
    """
    Yield a temporary directory that becomes `out`, whole, when the block completes.

    Parameters
    ----------
    option : str
        The option that named it (``'--out'``), [-]
    out : str or pathlib.Path
        The output directory, [-]
    command : str
        The subcommand writing it, recorded in :data:`MARKER`, [-]
    inputs : sequence of path
        What the command reads, never replaced, [-]
    force : bool
        Replace an existing directory that is not an earlier output of `command`, [-]

    Yields
    ------
    pathlib.Path
        Where to write; it is renamed to `out` when the block ends without an exception.

    Raises
    ------
    CliError
        If `out` is an input or exists and may not be replaced.

    """
    target, temporary = _prepare(option, out, command, written_by(command), inputs, force)
    shutil.rmtree(temporary, ignore_errors=True)
    temporary.mkdir()
    try:
        yield temporary
        write_marker(temporary, command)
        _commit(temporary, target, option, command, force, written_by(command))
    except BaseException:
        shutil.rmtree(temporary, ignore_errors=True)
        raise


@contextmanager
def output_file(option: str, out: str | Path, command: str, ours: Callable[[Path], bool],
                inputs: Sequence[str | Path] = (), force: bool = False) -> Iterator[Path]:
    """
    Yield a temporary file name that becomes `out` when the block completes.

    Parameters
    ----------
    option : str
        The option that named it (``'--out'``), [-]
    out : str or pathlib.Path
        The output file (or directory written as one piece, e.g. a bag), [-]
    command : str
        The subcommand writing it, for the message, [-]
    ours : callable
        Whether an existing `out` is an earlier output of `command`, [-]
    inputs : sequence of path
        What the command reads, never replaced, [-]
    force : bool
        Replace an existing `out` that is not an earlier output of `command`, [-]

    Yields
    ------
    pathlib.Path
        Where to write; renamed to `out` when the block ends without an exception.

    Raises
    ------
    CliError
        If `out` is an input or exists and may not be replaced.

    """
    target, temporary = _prepare(option, out, command, ours, inputs, force)
    try:
        yield temporary
        _commit(temporary, target, option, command, force, ours)
    except BaseException:
        if temporary.is_dir() and not temporary.is_symlink():
            shutil.rmtree(temporary, ignore_errors=True)
        else:
            temporary.unlink(missing_ok=True)
        raise


def png_by(command: str) -> Callable[[Path], bool]:
    """Return the check that a PNG was written by `command` (its ``Software`` text chunk)."""
    needle = f'Software\0satmotor {command}'.encode('latin-1')

    def ours(path: Path) -> bool:
        try:
            with path.open('rb') as file:
                head = file.read(4096)
        except OSError:
            return False
        return head.startswith(b'\x89PNG') and needle in head
    return ours


def png_metadata(command: str) -> dict[str, str]:
    """Return the PNG metadata that marks a figure as written by `command`."""
    return {'Software': f'satmotor {command}'}


__all__ = ['MARKER', 'check_target', 'clean_stale', 'output_dir', 'output_file', 'png_by',
           'png_metadata', 'resolve', 'write_marker', 'written_by']
