"""One message style for config errors: ``"<field.path>: <what is wrong> (got <value>)"``."""

from __future__ import annotations

from pydantic import ValidationError


def field_errors(exc: Exception, prefix: str = "") -> str:
    """Join a pydantic ``ValidationError`` (or any error) into one line naming each field."""
    if not isinstance(exc, ValidationError):
        return f"{prefix}: {exc}" if prefix else str(exc)
    lines = []
    for err in exc.errors():
        loc = ".".join(str(p) for p in err["loc"])
        loc = ".".join(p for p in (prefix, loc) if p) or "(top level)"
        msg = err["msg"].removeprefix("Value error, ")
        got = err.get("input")
        got_text = "" if isinstance(got, dict | list) or err["type"] == "value_error" else f" (got {got!r})"
        lines.append(f"{loc}: {msg}{got_text}")
    return "; ".join(lines)
