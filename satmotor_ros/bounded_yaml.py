# SPDX-License-Identifier: Apache-2.0
"""
YAML files read with bounded work: size, nesting, alias expansion, integer digits.

Every YAML file the package reads (motor files, column mappings, a bag's
``metadata.yaml``) goes through :func:`read_yaml`. A small hostile file must
not take unbounded memory or time, nor end in a traceback: a path that is not a
regular file (a FIFO would block forever, ``/dev/zero`` never end), a file larger
than ``YAML_MAX_BYTES``, nesting deeper than ``YAML_MAX_DEPTH``, aliases that would
expand to more than ``YAML_MAX_NODES`` nodes (a "billion laughs" bomb), an integer
of more than ``YAML_MAX_DIGITS`` digits (hex, octal, binary and sexagesimal ones
too: their letters count) and a key given twice are each refused with one line. The document is
never expanded into an error message. The caps live in :mod:`satmotor_ros.limits`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from satmotor_ros.limits import (LimitError, read_capped, YAML_MAX_BYTES, YAML_MAX_DEPTH,
                                 YAML_MAX_DIGITS, YAML_MAX_NODES)
import yaml


class YamlLimitError(ValueError):
    """A YAML file is malformed or exceeds a cap; the message is one line without the document."""


def _too_deep() -> YamlLimitError:
    return YamlLimitError(f'nesting deeper than {YAML_MAX_DEPTH} levels '
                          '(the cap SATMOTOR_YAML_MAX_DEPTH)')


def _too_large() -> YamlLimitError:
    return YamlLimitError(f'larger than {YAML_MAX_BYTES} bytes (the cap SATMOTOR_YAML_MAX_BYTES)')


class _BoundedLoader(yaml.SafeLoader):
    """A safe loader that counts depth and expanded size while it composes."""

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        self._depth = 0
        self._sizes: dict[int, int] = {}

    def compose_node(self, parent: Any, index: Any) -> Any:
        self._depth += 1
        if self._depth > YAML_MAX_DEPTH:
            raise _too_deep()
        try:
            node = super().compose_node(parent, index)
        finally:
            self._depth -= 1
        return node

    def compose_document(self) -> Any:
        node = super().compose_document()
        if node is not None and self._expanded(node) > YAML_MAX_NODES:
            raise YamlLimitError(f'aliases expand to more than {YAML_MAX_NODES} nodes '
                                 '(the cap SATMOTOR_YAML_MAX_NODES)')
        return node

    def _expanded(self, node: Any) -> int:
        """Count the nodes with every alias expanded, each shared node once (memoised)."""
        known = self._sizes.get(id(node))
        if known is not None:
            return known
        size = 1
        if isinstance(node, yaml.SequenceNode):
            size += sum(self._expanded(child) for child in node.value)
        elif isinstance(node, yaml.MappingNode):
            size += sum(self._expanded(k) + self._expanded(v) for k, v in node.value)
        self._sizes[id(node)] = size = min(size, YAML_MAX_NODES + 1)
        return size

    def construct_yaml_int(self, node: Any) -> Any:
        # every letter or digit: 0x/0o/0b prefixes and hex digits count too, underscores
        # and the colons of a sexagesimal 1:30:00 do not; 40 of them stay a finite float
        digits = sum(c.isalnum() for c in str(node.value))
        if digits > YAML_MAX_DIGITS:
            raise YamlLimitError(f'line {node.start_mark.line + 1}: an integer of {digits} '
                                 f'digits (at most {YAML_MAX_DIGITS})')
        return super().construct_yaml_int(node)

    def construct_mapping(self, node: Any, deep: bool = False) -> Any:
        seen: set[Any] = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)
            if isinstance(key, (str, int, float, bool)) and key in seen:
                raise YamlLimitError(f'line {key_node.start_mark.line + 1}: key {key!r} is '
                                     'given twice')
            seen.add(key)
        return super().construct_mapping(node, deep=deep)


_BoundedLoader.add_constructor('tag:yaml.org,2002:int', _BoundedLoader.construct_yaml_int)


def shown(value: Any, limit: int = 40) -> str:
    """
    Return the repr of a value read from a file, cut to `limit` characters for an error line.

    Parameters
    ----------
    value : Any
        The value, [-]
    limit : int
        Most characters shown, [-]

    Returns
    -------
    str
        ``repr(value)``, or its first characters and how long it is.

    """
    text = repr(value)
    return text if len(text) <= limit else f'{text[:limit]}... ({len(text)} characters)'


def parse_yaml(text: str) -> Any:
    """
    Parse one YAML document with the caps of this module.

    Parameters
    ----------
    text : str
        The document, [-]

    Returns
    -------
    Any
        The parsed document (mappings, lists, str, int, float, bool, None).

    Raises
    ------
    YamlLimitError
        If the text is not valid YAML or exceeds a cap; one line, without the document.

    """
    if len(text) > YAML_MAX_BYTES:
        raise _too_large()
    loader = None
    try:
        loader = _BoundedLoader(text)  # its reader refuses control characters here
        return loader.get_single_data()
    except yaml.YAMLError as err:
        problem = getattr(err, 'problem', None) or str(err).splitlines()[0]
        mark = getattr(err, 'problem_mark', None)
        where = f'line {mark.line + 1}: ' if mark is not None else ''
        raise YamlLimitError(f'not valid YAML ({where}{problem})') from None
    except RecursionError:
        raise _too_deep() from None
    finally:
        if loader is not None:
            loader.dispose()


def read_yaml(path: str | Path) -> Any:
    """
    Read and parse a YAML file, reading at most ``YAML_MAX_BYTES`` + 1 bytes.

    Parameters
    ----------
    path : str or pathlib.Path
        The file, [-]

    Returns
    -------
    Any
        The parsed document.

    Raises
    ------
    OSError
        If the file cannot be read.
    YamlLimitError
        If it is not a regular file (a FIFO would block), not UTF-8 YAML or exceeds
        a cap; one line, without the document.

    """
    try:
        data = read_capped(path, YAML_MAX_BYTES, 'SATMOTOR_YAML_MAX_BYTES')
    except LimitError as err:
        raise YamlLimitError(str(err)) from None
    try:
        text = data.decode('utf-8')
    except UnicodeDecodeError as err:
        raise YamlLimitError(f'not UTF-8 text (byte {err.start})') from None
    return parse_yaml(text)


def read_yaml_or(path: str | Path, error: type[Exception], unreadable: str,
                 hostile: str) -> Any:
    """
    Read and parse a YAML file as :func:`read_yaml` does, any failure one `error` line.

    Parameters
    ----------
    path : str or pathlib.Path
        The file, [-]
    error : type
        The exception to raise (the caller's own kind of error), [-]
    unreadable : str
        What a file that cannot be read is called: ``'<unreadable>: <strerror>'``, [-]
    hostile : str
        What a file beyond a cap or not YAML is called: ``'<hostile>: <reason>'``, [-]

    Returns
    -------
    Any
        The parsed document.

    """
    try:
        return read_yaml(path)
    except OSError as err:
        raise error(f'{unreadable}: {err.strerror}') from None
    except YamlLimitError as err:
        raise error(f'{hostile}: {err}') from None


__all__ = ['YamlLimitError', 'parse_yaml', 'read_yaml', 'read_yaml_or', 'shown']
