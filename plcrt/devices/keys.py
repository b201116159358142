"""The one check every table of a plant file gets: it is a table, it has
the keys it must have, and it has no key the reader does not know (a misspelt key would otherwise be
ignored and the plant silently differ from what its author wrote).

What it is not: the checks of the values; each reader does those.
"""

from __future__ import annotations

from typing import Any

from ..errors import PlcConfigError

__all__ = ["checked_table"]


def checked_table(raw: Any, where: str, keys: set[str],
                  required: tuple[str, ...] = ()) -> dict:
    """*raw* if it is a table with only *keys* and all of *required*; else a
    PlcConfigError at *where*."""
    if not isinstance(raw, dict):
        raise PlcConfigError(f"{where} must be a table")
    unknown = set(raw) - keys
    if unknown:
        raise PlcConfigError(f"{where}: unknown key(s) {', '.join(sorted(map(str, unknown)))} "
                             f"(known: {', '.join(sorted(keys))})")
    for key in required:
        if key not in raw:
            raise PlcConfigError(f"{where}: {key} is missing")
    return raw
