"""Reading a TOML file (a study, a vehicle file) with one message style: ``"<file>: <what is wrong>"``.

Shared by every layer that reads user files (:mod:`railopt.models.vehicle.loader`,
:mod:`railopt.studies.config`); each raises ``ValueError`` and the caller turns it into its own error class.
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path
from typing import Any

__all__ = ["read_toml"]

_HEADER = re.compile(r"^\s*\[\[?\s*([^\]]+?)\s*\]\]?")
_KEY = re.compile(r"([A-Za-z0-9_\-]+)\s*=\s*")


def _long_integer_key(text: str) -> str | None:
    """``"table.key"`` (or ``"line N"``) of the first integer literal over Python's int-string digit limit."""
    table = ""
    for n, line in enumerate(text.splitlines(), start=1):
        header = _HEADER.match(line)
        if header and "=" not in line.split("]")[0]:
            table = header.group(1).strip().replace('"', "")
            continue
        digits = re.search(r"(?<![\w.])[+-]?[0-9][0-9_]{4300,}", line)
        if digits:
            keys = [m.group(1) for m in _KEY.finditer(line[:digits.start()])]
            if not keys:
                return f"line {n}"
            return ".".join([table] * bool(table) + keys[:1] + keys[1:][-1:])
    return None


def read_toml(path: str | Path, what: str = "study") -> dict[str, Any]:
    """The parsed TOML of ``path``; every failure is a ``ValueError`` ``"<file>: <what is wrong>"`` (unreadable,
    not UTF-8, not TOML, nested too deeply, an integer over Python's int-string limit — naming its key)."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise ValueError(f"{path}: cannot read the {what} file ({exc.strerror})") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ValueError(f"{path}: not a text file (byte {exc.start} is not UTF-8); a {what} is a TOML file") \
            from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{path}: not valid TOML ({exc})") from None
    except RecursionError:
        raise ValueError(f"{path}: not valid TOML (nested too deeply)") from None
    except ValueError as exc:  # an integer over Python's int-string limit (4300 digits): not a TOMLDecodeError
        key = _long_integer_key(text)
        where = f"{key}: " if key else ""
        limit = "the int-string limit" if "limit" not in str(exc) else str(exc).split(":")[0].strip()
        raise ValueError(f"{path}: {where}integer too long to read ({limit}); no field takes a number that large") \
            from None
