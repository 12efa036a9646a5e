"""
Bounded parsers
===============

Parsers of untrusted n, k files whose work is bounded *before* it is done:
the text size, the nesting depth, the node count and the table size are
checked while (or before) the document is built, never after, so a small
hostile file cannot make a large amount of work or memory.

-   :func:`load_json_bounded`: ``json.loads`` after a depth scan; refuses
    ``NaN`` / ``Infinity`` literals.
-   :func:`load_yaml_bounded`: a safe YAML load that refuses aliases (the
    "billion laughs" expansion), merge keys, and documents nested deeper
    than :data:`MAX_DEPTH` or with more than :data:`MAX_YAML_NODES` nodes.
-   :func:`csv_rows_bounded`: CSV rows, with the row count, the line length
    and the column count bounded.
-   :func:`check_sample_count`: the number of samples of a formula entry
    over a wavelength range, refused before anything is allocated.
-   :func:`excerpt`: a short, printable excerpt of bad input for a message.
-   :func:`kind_of`: what a parsed value is, in words ("a list", "a date").

Every refusal is a ``ValueError`` naming the limit and its value.
"""

from __future__ import annotations

import csv
import datetime
import io
import json
import math
import re
from typing import Any

import numpy as np

__all__ = [
    "MAX_TEXT_CHARS",
    "MAX_DEPTH",
    "MAX_YAML_NODES",
    "MAX_SAMPLES",
    "MAX_CSV_COLUMNS",
    "MAX_LINE_CHARS",
    "MAX_EXCERPT_CHARS",
    "excerpt",
    "kind_of",
    "check_text_size",
    "load_json_bounded",
    "load_yaml_bounded",
    "csv_rows_bounded",
    "check_sample_count",
    "is_number",
    "parse_number",
]

MAX_TEXT_CHARS = 4_000_000
"""Longest file text accepted by the readers (characters)."""
MAX_DEPTH = 32
"""Deepest nesting of JSON arrays/objects or YAML collections (an n, k file needs 3)."""
MAX_YAML_NODES = 20_000
"""Most YAML nodes (scalars, sequences, mappings) in one document."""
MAX_SAMPLES = 100_000
"""Most wavelength samples in one table: CSV rows, YAML data rows, JSON list items, formula samples."""
MAX_CSV_COLUMNS = 16
"""Most columns in one CSV row (the reader needs 3)."""
MAX_LINE_CHARS = 1_000
"""Longest line of a CSV file or of a YAML data table (characters)."""
MAX_EXCERPT_CHARS = 60
"""Longest excerpt of bad input repeated in a message."""


def excerpt(value: Any, limit: int = MAX_EXCERPT_CHARS) -> str:
    """
    ``value`` as a short printable string for an error message: at most
    ``limit`` characters of its ``repr`` (strings are shown quoted), with
    ``...`` when cut.
    """
    text = repr(value) if not isinstance(value, str) else repr(value[: limit + 1])
    text = text.encode("ascii", "backslashreplace").decode("ascii")
    return text if len(text) <= limit else text[: limit - 3] + "..."


def kind_of(value: Any) -> str:
    """What a parsed value is, in words, for a message about a wrong type."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return f"a boolean ({value})"
    if isinstance(value, (int, float)):
        return f"a number ({excerpt(value, 30)})"
    if isinstance(value, (bytes, bytearray)):
        return "binary data"
    if isinstance(value, (datetime.date, datetime.datetime)):
        return f"a date ({value})"
    if isinstance(value, (list, tuple)):
        return "a list"
    if isinstance(value, dict):
        return "a map"
    if isinstance(value, (set, frozenset)):
        return "a set"
    return f"{type(value).__name__}"


def check_text_size(text: str | bytes, what: str, limit: int = MAX_TEXT_CHARS) -> None:
    """Refuse a file text longer than ``limit`` characters (or bytes)."""
    if len(text) > limit:
        raise ValueError(f"{what} must be at most {limit} characters long, got {len(text)}")


# A complete JSON string literal (escapes included); what lies between two of
# them is structure, numbers and literals.
_JSON_STRING = re.compile(r'"(?:[^"\\]|\\.)*"', re.DOTALL)


def _json_depth(text: str) -> int:
    """Deepest bracket nesting of a JSON text, strings skipped (C-speed: regex + numpy)."""
    structure = _JSON_STRING.sub("", text)
    codes = np.frombuffer(structure.encode("utf-8", "surrogatepass"), dtype=np.uint8)
    steps = np.isin(codes, (0x5B, 0x7B)).astype(np.int32) - np.isin(codes, (0x5D, 0x7D)).astype(np.int32)
    return int(np.cumsum(steps).max(initial=0))


class _NonFiniteLiteral(ValueError):
    pass


_NUMBER = re.compile(
    r"[+-]?(?:(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|inf(?:inity)?|nan)", re.IGNORECASE | re.ASCII
)


def is_number(text: str) -> bool:
    """Whether ``text`` is a number :func:`parse_number` reads."""
    return isinstance(text, str) and _NUMBER.fullmatch(text.strip()) is not None


def parse_number(text: str, what: str) -> float:
    """
    ``text`` (surrounding spaces allowed) as a float when it is a decimal
    number in ASCII digits, e.g. ``-1.5e3`` (``inf`` and ``nan`` too, for the
    finiteness checks to name): Python's ``float`` also reads full-width and
    Arabic-Indic digits and ``6_00``, which no n, k file means as numbers.

    Raises
    ------
    ValueError
        ``"`what` must be a number in ASCII digits, got ..."``.
    """
    if not is_number(text):
        raise ValueError(f"{what} must be a number in ASCII digits, got {excerpt(text, 40)}")
    return float(text)


def _refuse_constant(name: str) -> float:
    raise _NonFiniteLiteral(f"JSON numbers must be finite: the literal `{name}` is not accepted")


def load_json_bounded(text: str | bytes, max_depth: int = MAX_DEPTH, max_chars: int = MAX_TEXT_CHARS) -> Any:
    """
    Parse JSON text whose size is at most ``max_chars`` and whose arrays and
    objects nest at most ``max_depth`` deep (scanned before parsing, so deep
    nesting never reaches the recursive decoder). ``NaN``, ``Infinity`` and
    ``-Infinity`` are refused.

    Raises
    ------
    ValueError
        Naming the broken limit, or the decoder's message for invalid JSON.
    """
    check_text_size(text, "JSON", max_chars)
    if isinstance(text, bytes):
        try:
            text = text.decode("utf-8-sig")
        except UnicodeDecodeError:
            raise ValueError("JSON must be UTF-8 text") from None
    text = text.removeprefix("\ufeff")
    depth = _json_depth(text)
    if depth > max_depth:
        raise ValueError(f"JSON must nest at most {max_depth} levels deep, got {depth}")
    try:
        return json.loads(text, parse_constant=_refuse_constant)
    except json.JSONDecodeError as error:
        raise ValueError(f"JSON is not valid: {error.msg} at line {error.lineno} column {error.colno}") from None
    except RecursionError:  # unreachable after the depth scan; kept as a guard
        raise ValueError(f"JSON must nest at most {max_depth} levels deep") from None
    except _NonFiniteLiteral as error:
        raise ValueError(str(error)) from None
    except ValueError as error:
        # int() refuses more than 4300 digits; _refuse_constant's own message.
        raise ValueError(f"JSON is not valid: {excerpt(str(error), 120)[1:-1]}") from None


class _YamlLimit(ValueError):
    """A bound of the YAML loader (aliases, depth, nodes): its message is final."""


def _check_plain_number(value: str) -> None:
    if "_" in value:
        raise _YamlLimit(f"YAML number {excerpt(value, 40)} must be written without `_`")


def _yaml_loader(max_depth: int, max_nodes: int):
    """A SafeLoader class whose composer counts nodes and depth and refuses aliases."""
    import yaml
    from yaml.composer import Composer
    from yaml.events import AliasEvent, MappingStartEvent, SequenceStartEvent
    from yaml.resolver import Resolver

    try:
        from yaml._yaml import CParser  # libyaml: fast, and its parser is not recursive

        parser_bases: tuple[type, ...] = (CParser,)
    except ImportError:  # pragma: no cover - PyYAML without libyaml
        from yaml.parser import Parser
        from yaml.reader import Reader
        from yaml.scanner import Scanner

        parser_bases = (Reader, Scanner, Parser)

    class BoundedComposer(Composer):
        """PyYAML's composer with a node budget, a depth limit and no aliases."""

        def compose_document(self):
            self._nodes, self._depth = 0, 0
            return super().compose_document()

        def compose_node(self, parent, index):
            event = self.peek_event()
            if isinstance(event, AliasEvent):
                raise _YamlLimit(
                    f"YAML aliases (`*{excerpt(event.anchor, 30)[1:-1]}`) are not accepted: "
                    "an n, k file has no repeated parts"
                )
            self._nodes += 1
            if self._nodes > max_nodes:
                raise _YamlLimit(f"YAML must have at most {max_nodes} nodes")
            nested = isinstance(event, (SequenceStartEvent, MappingStartEvent))
            if nested:
                self._depth += 1
                if self._depth > max_depth:
                    raise _YamlLimit(f"YAML must nest at most {max_depth} levels deep")
            try:
                return super().compose_node(parent, index)
            finally:
                if nested:
                    self._depth -= 1

    class BoundedSafeConstructor(yaml.constructor.SafeConstructor):
        def construct_yaml_int(self, node):
            # YAML 1.1 reads `6_00` as 600: refused, as in every other number read.
            _check_plain_number(self.construct_scalar(node))
            return super().construct_yaml_int(node)

        def construct_yaml_float(self, node):
            _check_plain_number(self.construct_scalar(node))
            return super().construct_yaml_float(node)

        def flatten_mapping(self, node):
            for key, _ in node.value:
                if key.tag == "tag:yaml.org,2002:merge":
                    raise _YamlLimit("YAML merge keys (`<<`) are not accepted")
            super().flatten_mapping(node)

    # The tag table holds SafeConstructor's functions: the overrides are registered anew.
    BoundedSafeConstructor.add_constructor("tag:yaml.org,2002:int", BoundedSafeConstructor.construct_yaml_int)
    BoundedSafeConstructor.add_constructor("tag:yaml.org,2002:float", BoundedSafeConstructor.construct_yaml_float)

    # The composer comes first, so that compose_* and get_*node are its own,
    # not libyaml's (which composes natively and expands aliases).
    class BoundedLoader(BoundedComposer, *parser_bases, BoundedSafeConstructor, Resolver):
        def __init__(self, stream):
            for base in parser_bases:
                if base.__name__ == "CParser" or base.__name__ == "Reader":
                    base.__init__(self, stream)
                else:
                    base.__init__(self)
            BoundedComposer.__init__(self)
            BoundedSafeConstructor.__init__(self)
            Resolver.__init__(self)

    return BoundedLoader


_LOADERS: dict[tuple[int, int], type] = {}


def load_yaml_bounded(
    text: str | bytes, max_depth: int = MAX_DEPTH, max_nodes: int = MAX_YAML_NODES, max_chars: int = MAX_TEXT_CHARS
) -> Any:
    """
    Safe-load one YAML document of at most ``max_chars`` characters,
    ``max_nodes`` nodes and ``max_depth`` levels of nesting; aliases and
    merge keys are refused while the document is composed, before any
    expansion.

    Raises
    ------
    ValueError
        Naming the broken limit, or the parser's problem for invalid YAML.
    """
    import yaml

    check_text_size(text, "YAML", max_chars)
    key = (max_depth, max_nodes)
    if key not in _LOADERS:
        _LOADERS[key] = _yaml_loader(max_depth, max_nodes)
    loader = _LOADERS[key](text)
    try:
        return loader.get_single_data()
    except yaml.MarkedYAMLError as error:
        where = f" at line {error.problem_mark.line + 1}" if error.problem_mark else ""
        problem = excerpt(str(error.problem or error.context or "syntax error"), 80)[1:-1]
        raise ValueError(f"YAML is not valid: {problem}{where}") from None
    except yaml.YAMLError as error:
        raise ValueError(f"YAML is not valid: {excerpt(str(error), 80)[1:-1]}") from None
    except RecursionError:
        raise ValueError(f"YAML must nest at most {max_depth} levels deep") from None
    except _YamlLimit as error:
        raise ValueError(str(error)) from None
    except (ValueError, TypeError, OverflowError) as error:
        # A tagged scalar that does not construct (`!!float abc`, a date out
        # of range, an integer of 5,000 digits): Python's message may repeat
        # the whole scalar, so only an excerpt is kept.
        raise ValueError(f"YAML is not valid: a value could not be read ({excerpt(str(error), 80)[1:-1]})") from None
    finally:
        loader.dispose()


def csv_rows_bounded(
    text: str, max_rows: int = MAX_SAMPLES + 1, max_columns: int = MAX_CSV_COLUMNS, max_line_chars: int = MAX_LINE_CHARS
) -> list[list[str]]:
    """
    The non-blank rows of a CSV text, refusing more than ``max_rows`` lines,
    a line or a (quoted, multi-line) field longer than ``max_line_chars``, or
    a row of more than ``max_columns`` fields; the line count and length are
    checked before the rows are built, the others row by row.
    """
    check_text_size(text, "CSV")
    lines = text.rstrip().count("\n") + 1  # a final newline (or blank lines) ends the last row
    if lines > max_rows:
        raise ValueError(f"CSV must have at most {max_rows} lines, got {lines}")
    longest = max(map(len, text.splitlines()), default=0)
    if longest > max_line_chars:
        raise ValueError(f"CSV lines must be at most {max_line_chars} characters long, got {longest}")
    rows = []
    try:
        for line, row in enumerate(csv.reader(io.StringIO(text)), start=1):
            if len(row) > max_columns:
                raise ValueError(f"CSV line {line} must have at most {max_columns} columns, got {len(row)}")
            longest = max(map(len, row), default=0)
            if longest > max_line_chars:  # a quoted field spanning lines
                raise ValueError(
                    f"CSV fields must be at most {max_line_chars} characters long, got {longest} in row {line}"
                )
            if row and any(cell.strip() for cell in row):
                rows.append(row)
    except csv.Error as error:
        raise ValueError(f"CSV is malformed: {excerpt(str(error), 80)[1:-1]}") from None
    return rows


def check_sample_count(lo: float, hi: float, step: float, what: str, limit: int = MAX_SAMPLES) -> int:
    """
    The number of samples ``step`` apart over ``[lo, hi]`` (same unit),
    refused when the range is not finite and increasing or when the count
    exceeds ``limit``; computed from the bounds alone, before any array is made.
    """
    if not (math.isfinite(lo) and math.isfinite(hi)) or not lo < hi:
        raise ValueError(f"{what} must be two finite increasing numbers, got [{lo:g}, {hi:g}]")
    count = math.floor((hi - lo) / step + 0.5) + 1
    if count > limit:
        raise ValueError(
            f"{what} [{lo:g}, {hi:g}] would need {count} samples {step:g} apart; at most {limit} are allowed"
        )
    return max(2, count)
