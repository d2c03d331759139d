"""A decoded message as named cells, the columns and text `orbed-log export --csv` writes
(lcmtypes/flat_row.h): a column is the field's path (nested structs joined by '.', array elements as
'[i]') with its unit in parentheses when it has one; the units come from gen_flatten.py through
orbed_lcm._structure. A byte array is one cell, its length in bytes ("data (bytes)").

Cell text: integers in decimal, booleans 1/0, floating point as C++'s std::to_chars shortest form
(shortest digits that read back to the same double, or float for `float` fields; fixed or
scientific notation, whichever is shorter, fixed on a tie; "nan", "inf", "-inf"), strings as they
are; in a CSV file (csv_cell) quoted as RFC 4180 when they hold a comma, quote, CR or LF or start
or end with a space. Pure.
"""
import math

import numpy as np

from orbed import types
from orbed.wire import PRIMITIVE_BYTES


def _shortest_digits(value, is_float32):
    """(digits, x) of |value| != 0 with value = d.ddd * 10^x: the shortest digits that read back
    to the same double (Python's repr) or float (numpy's unique formatting)."""
    text = (np.format_float_scientific(np.float32(abs(value)), unique=True, trim="-") if is_float32
            else repr(abs(value)))
    mantissa, _, exponent = text.partition("e")
    whole, _, fraction = mantissa.partition(".")
    all_digits = whole + fraction
    leading_zeros = len(all_digits) - len(all_digits.lstrip("0"))
    x = int(exponent or 0) + len(whole) - 1 - leading_zeros
    return all_digits.strip("0"), x


def shortest(value, is_float32=False):
    """`value` as std::to_chars(double or float) writes it."""
    if math.isnan(value):
        return "nan"
    if math.isinf(value):
        return "inf" if value > 0 else "-inf"
    sign = "-" if math.copysign(1.0, value) < 0 else ""
    if value == 0:
        return sign + "0"
    digits, x = _shortest_digits(value, is_float32)
    n = len(digits)
    scientific = digits[0] + ("." + digits[1:] if n > 1 else "") + "e" + ("-" if x < 0 else "+") + f"{abs(x):02d}"
    if x >= n - 1:
        fixed = str(int(abs(value)))  # an integer in fixed notation is written exactly
        if len(fixed) != x + 1:  # cannot happen for a round-tripping value; be safe
            fixed = digits + "0" * (x - n + 1)
    elif x >= 0:
        fixed = digits[:x + 1] + "." + digits[x + 1:]
    else:
        fixed = "0." + "0" * (-x - 1) + digits
    return sign + (fixed if len(fixed) <= len(scientific) else scientific)


def csv_cell(text):
    """`text` as one CSV cell (RFC 4180 quoting when needed)."""
    if any(c in text for c in ',"\r\n') or (text and (text[0] == " " or text[-1] == " ")):
        return '"' + text.replace('"', '""') + '"'
    return text


def _cell(type_name, value):
    if type_name == "boolean":
        return "1" if value else "0"
    if type_name in ("double", "float"):
        return shortest(float(value), type_name == "float")
    if type_name == "string":
        return value
    return str(int(value))


def flatten(message, prefix="", out=None, struct_name=None):
    """[(column name, cell text, value)] of `message` in field order (value: the Python value; for a
    byte array its length; for a float field the double its text reads as)."""
    structs = types.structs()
    out = [] if out is None else out
    for type_name, field, dims, unit in structs[struct_name or type(message).__name__]:
        value = getattr(message, field)
        if type_name == "byte" and dims:
            out.append((f"{prefix}{field} (bytes)", str(len(value)), len(value)))
            continue
        _flatten_field(message, structs, type_name, f"{prefix}{field}", dims, unit, value, out)
    return out


def _flatten_field(message, structs, type_name, path, dims, unit, value, out):
    if dims:
        bound = int(dims[0]) if dims[0].isdigit() else int(getattr(message, dims[0]))
        for i in range(bound):
            _flatten_field(message, structs, type_name, f"{path}[{i}]", dims[1:], unit, value[i], out)
    elif type_name in PRIMITIVE_BYTES or type_name == "string":
        cell = _cell(type_name, value)
        if type_name == "float":
            value = float(cell)  # the double its CSV text reads as (0.1, not 0.10000000149011612)
        out.append((f"{path} ({unit})" if unit else path, cell, value))
    else:
        flatten(value, path + ".", out, type_name)
