# SPDX-License-Identifier: Apache-2.0
"""
What a bag records about itself: rosbag2's ``custom_data`` (metadata.yaml, format 9).

The bags this package writes (the demo's runs, ``replay --out-bag``) record the liquid and
the motor of the run under :data:`LIQUID_KEY` and :data:`MOTOR_KEY`; ``ros2 bag record
--custom-data satmotor.liquid=water`` records them on a bench. The metadata belongs to the
whole recording and costs no message, so a reader knows them before the first message.
"""

from __future__ import annotations

from pathlib import Path

from satmotor_ros.bags.errors import BagError
from satmotor_ros.bounded_yaml import parse_yaml, read_yaml, YamlLimitError

LIQUID_KEY = 'satmotor.liquid'
"""custom_data key of the run's coefficient set and liquid ('oil', 'water' or a set's name)."""

MOTOR_KEY = 'satmotor.motor'
"""custom_data key of the run's motor: its name (e.g. 'SM-0,75/25'), or the motor file."""


def _from_info(doc: object) -> dict[str, str]:
    # metadata.yaml nests it; the MCAP file's rosbag2 record holds the inner mapping alone
    info = doc.get('rosbag2_bagfile_information', doc) if isinstance(doc, dict) else None
    custom = info.get('custom_data') if isinstance(info, dict) else None
    if not isinstance(custom, dict):
        return {}
    return {str(k): str(v) for k, v in custom.items() if v is not None}


def _from_mcap(path: Path) -> dict[str, str]:
    from mcap.reader import make_reader

    try:
        with path.open('rb') as stream:
            for record in make_reader(stream).iter_metadata():
                if record.name == 'rosbag2':
                    return _from_info(parse_yaml(record.metadata.get('serialized_metadata',
                                                                     '')))
    except (OSError, ValueError, KeyError, TypeError, YamlLimitError) as err:
        raise BagError(f'{path}: cannot read its metadata ({err})') from None
    except Exception:  # noqa: BLE001  mcap raises its own errors on a damaged summary
        return {}
    return {}


def custom_data(path: str | Path) -> dict[str, str]:
    """
    Read the custom_data a bag recorded.

    Parameters
    ----------
    path : str or pathlib.Path
        Bag directory (its metadata.yaml) or a single ``.mcap`` file (its rosbag2
        metadata record); anything else records nothing, [-]

    Returns
    -------
    dict of str to str
        Key -> value; empty when the bag records none.

    Raises
    ------
    BagError
        If metadata.yaml cannot be read.

    """
    path = Path(path)
    if path.is_dir():
        meta = path / 'metadata.yaml'
        if not meta.is_file():
            return {}
        try:
            return _from_info(read_yaml(meta))
        except (OSError, ValueError, YamlLimitError) as err:
            raise BagError(f'{meta}: cannot read it ({err})') from None
    if path.is_file() and path.name.endswith('.mcap'):
        return _from_mcap(path)
    return {}


__all__ = ['LIQUID_KEY', 'MOTOR_KEY', 'custom_data']
