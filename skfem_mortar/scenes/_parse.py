"""Command-line values of scene parameters: booleans, integers and plain numbers
(:meth:`skfem_mortar.scenes.Param.parse` calls these)."""
from __future__ import annotations

import re
from typing import Any

import numpy as np

#: a number as the command line takes it: ASCII digits, an optional sign, decimal
#: point and exponent.  Python's float() and int() also take "1_0" (its literal
#: syntax for 10, more likely a typo of 1.0), other scripts' digits and "inf": refused
_PLAIN_NUMBER = re.compile(r"[+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?")


def plain_number(text: str) -> bool:
    """Whether ``text`` (surrounding blanks aside) is a plain number (:data:`_PLAIN_NUMBER`)."""
    return _PLAIN_NUMBER.fullmatch(text.strip()) is not None


def to_bool(value: Any) -> bool:
    """``1/0, true/false, yes/no, on/off`` (strings), a bool, or the numbers 0 and 1."""
    if isinstance(value, str):
        low = value.strip().lower()
        if low not in ("1", "0", "true", "false", "yes", "no", "on", "off"):
            raise ValueError(value)
        return low in ("1", "true", "yes", "on")
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, float, np.integer, np.floating)) and value in (0, 1):
        return bool(value)
    raise ValueError(value)


def to_int(value: Any) -> int:
    """An integer from an int, an integral float, or a string like ``"12"`` or ``"1e3"``."""
    if isinstance(value, (bool, np.bool_)):
        raise TypeError("a bool is not an integer")
    if isinstance(value, str):
        text = value.strip()
        try:
            return int(text)
        except ValueError:
            value = float(text)  # "1e3"; ValueError for anything else
    if isinstance(value, (float, np.floating)):
        if not float(value).is_integer():
            raise ValueError(value)
        return int(value)  # OverflowError for inf, ValueError for nan
    return int(value)
