"""Plain data (the mapping a config is read into) written back as TOML text.

``tomllib`` reads TOML but the standard library has no writer; configs written by the
package (a study's chosen configuration, a test's shrunk example) go through ``dumps``.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import PurePath
from typing import Any

_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")


def dumps(table: dict[str, Any]) -> str:
    """``table`` as TOML text that ``tomllib.loads`` reads back to the same mapping.

    Values may be strings, paths (written as strings), booleans, integers, floats
    (``inf``/``nan`` included), lists and nested mappings; a list whose items are all
    mappings becomes an array of tables (``[[key]]``), a mapping inside any other list an
    inline table. ``None`` has no TOML form: keys holding it are left out, so a config field
    whose default is ``None`` reads back the same.
    """
    return _table(table, prefix="").strip("\n") + "\n"


def _table(table: dict[str, Any], prefix: str) -> str:
    lines = [
        f"{_key(key)} = {_value(item)}"
        for key, item in table.items()
        if item is not None and not isinstance(item, dict) and not _is_tables(item)
    ]
    for key, item in table.items():
        name = f"{prefix}{_key(key)}"
        if isinstance(item, dict):
            lines += ["", f"[{name}]", _table(item, f"{name}.")]
        elif _is_tables(item):
            for entry in item:
                lines += ["", f"[[{name}]]", _table(entry, f"{name}.")]
    return "\n".join(lines).strip("\n")


def _is_tables(item: Any) -> bool:
    return isinstance(item, list) and bool(item) and all(isinstance(v, dict) for v in item)


def _key(key: str) -> str:
    return key if _BARE_KEY.fullmatch(key) else _string(key)


def _string(text: str) -> str:
    """A TOML basic string: JSON's escapes, which TOML shares, with characters beyond the
    BMP left as they are (JSON would write surrogates, which TOML refuses) and DEL escaped."""
    return json.dumps(text, ensure_ascii=False).replace("\x7f", "\\u007f")


def _value(item: Any) -> str:
    if isinstance(item, str):
        return _string(item)
    if isinstance(item, bool | int):
        return json.dumps(item)
    if isinstance(item, float):
        if math.isnan(item):
            return "nan"
        return ("-inf" if item < 0 else "inf") if math.isinf(item) else repr(item)
    if isinstance(item, PurePath):
        return _string(str(item))
    if isinstance(item, list | tuple):
        return "[" + ", ".join(_value(v) for v in item) + "]"
    if isinstance(item, dict):
        pairs = (f"{_key(k)} = {_value(v)}" for k, v in item.items() if v is not None)
        return "{ " + ", ".join(pairs) + " }"
    raise TypeError(f"no TOML form for {type(item).__name__} value {item!r}")
