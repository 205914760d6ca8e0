# SPDX-License-Identifier: Apache-2.0
"""
Remove what a fleet run wrote for recordings that are no longer under ROOT.

A recording deleted (or moved, renamed) leaves ``DIR/<motor>/<recording>/`` behind; a motor
gone, ``DIR/<motor>/``. They are removed only when everything in them is the fleet's own:
its markers and state files, and output directories their own marker says the tool wrote
whole (:func:`~satmotor_ros.cli._output.written_by`). A file a user put there keeps it.
"""

from __future__ import annotations

from pathlib import Path
import shutil

from satmotor_ros.fleet.discover import Motor

OWN_FILES = ('.fleet-done.json', '.fleet-monitor.json', '.monitor-state.json',
             '.fleet-change.json')
"""The files a fleet run writes in a recording's directory."""

MOTOR_FILES = ('baseline.json', 'columns.yaml')
"""The files a fleet run writes in a motor's directory."""


def prune(out: Path, root: Path, motors: list[Motor], report: tuple[str, ...]) -> list[str]:
    """
    Remove the directories of recordings and motors that are gone, where wholly ours.

    A DIR whose last report was of another ROOT is refused before (:func:`check_root`), or
    taken over with ``--force``: then the first ROOT's outputs go as a deleted recording's.

    Parameters
    ----------
    out : pathlib.Path
        DIR, [-]
    root : pathlib.Path
        ROOT, [-]
    motors : list of Motor
        The fleet as discovered now, [-]
    report : tuple of str
        The names of the report's own entries in DIR (fleet.json, plots...), never touched, [-]

    Returns
    -------
    list of str
        What was removed, relative to DIR.

    """
    current = {m.motor: {r.name for r in m.recordings} for m in motors}
    removed = []
    for motor in sorted(p for p in out.iterdir() if p.is_dir() and not p.is_symlink()):
        if motor.name in report or motor.name.startswith('.'):
            continue
        names = current.get(motor.name, set())
        for recording in sorted(p for p in motor.iterdir() if p.is_dir()
                                and not p.is_symlink() and p.name not in names):
            if _ours(recording):
                shutil.rmtree(recording)
                removed.append(f'{motor.name}/{recording.name}')
        if motor.name not in current and _our_motor(motor):
            shutil.rmtree(motor)
            removed.append(motor.name)
    return removed


def check_root(out: Path, root: Path, force: bool) -> str | None:
    """
    Refuse a DIR whose last fleet report was of another ROOT, unless forced.

    Parameters
    ----------
    out : pathlib.Path
        DIR, [-]
    root : pathlib.Path
        ROOT of this run, [-]
    force : bool
        Take DIR over for this ROOT, [-]

    Returns
    -------
    str or None
        The other ROOT DIR is taken over from (with `force`), else None.

    Raises
    ------
    FleetError
        One line naming both ROOTs, without `force`.

    """
    from satmotor_ros.fleet.errors import FleetError
    before, now = root_of(out), str(root.resolve())
    if before in (None, now):
        return None
    if not force:
        raise FleetError(f'--out {str(out)!r}: its last report is of ROOT {before!r}, not '
                         f'{now!r} (another --out, or --force to take it over: the outputs '
                         f'of {before!r} wholly written by satmotor fleet are removed)')
    return before


def root_of(out: Path) -> str | None:
    """Return the ROOT of DIR's last fleet report, or None (no report)."""
    from satmotor_ros.fleet.config import REPORT_JSON
    from satmotor_ros.fleet.resume import read_marker
    root = (read_marker(out / REPORT_JSON) or {}).get('root')
    return root if isinstance(root, str) else None


def _our_motor(directory: Path) -> bool:
    """
    Whether a motor's directory holds a baseline a fleet run wrote, and only our files.

    The baseline proves it: its ``key`` hashes the rest of it, as the run wrote it. A directory
    without one (empty, a user's ``columns.yaml`` or ``baseline.json``) is kept.
    """
    from satmotor_ros.fleet.resume import options_key, read_marker
    entries = list(directory.iterdir())
    if any(not p.is_file() or p.is_symlink() or p.name not in MOTOR_FILES for p in entries):
        return False
    baseline = read_marker(directory / MOTOR_FILES[0])
    if baseline is None or 'key' not in baseline:
        return False
    hashed = {k: v for k, v in baseline.items() if k not in ('key', 'stats')}
    return bool(baseline['key'] == options_key(hashed))


def _ours(directory: Path) -> bool:
    """Whether a recording's directory holds only what a fleet run writes (and a marker)."""
    from satmotor_ros.cli._output import written_by
    from satmotor_ros.fleet.tasks import MONITOR_DIR, OUTPUTS
    commands = {**OUTPUTS, MONITOR_DIR: 'monitor'}
    entries = list(directory.iterdir())
    if not any(p.name in OWN_FILES[:2] for p in entries):
        return False  # no marker of ours: not a recording's directory we made
    for entry in entries:
        if entry.is_symlink():
            return False
        if entry.is_file() and entry.name in OWN_FILES:
            continue
        if entry.is_dir() and entry.name in commands and written_by(commands[entry.name])(entry):
            continue
        return False
    return True


__all__ = ['MOTOR_FILES', 'OWN_FILES', 'check_root', 'prune', 'root_of']
