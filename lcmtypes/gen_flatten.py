#!/usr/bin/env python3
"""Generates orbed/flatten.hpp: for every struct of the .lcm files, a function that flattens a decoded
message into named cells with units, for `orbed-log export --csv` (the runtime half, FlatRow, is
lcmtypes/flat_row.h).

usage: gen_flatten.py OUTPUT.hpp FILE.lcm...

A cell is named by its path: nested structs with '.', array elements with '[i]' (X_WH.position_m[0],
contacts[2].distance_m). A byte array is one cell, its length in bytes. The unit of a field is, in this
order: the one unit in brackets of a comment about that field alone; its name's suffix (_m, _mm, _deg,
_rad, _s, _us, _px, _hz, _m2, _rad2); 'us' for utime; the one unit in brackets ([rad], [N m], [us since
the Unix epoch]) of the comment block above it, which covers the fields that follow it up to a blank
line or the next comment (its floating-point fields; counts keep no unit). Otherwise no unit.
The .lcm parser is gen_wire_checks.py's.
"""

import re
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
from gen_wire_checks import PRIMITIVE_BYTES, parse_lcm  # noqa: E402 (after the line above)

NAME_SUFFIX_UNITS = [("_rad2", "rad^2"), ("_m2", "m^2"), ("_mm", "mm"), ("_deg", "deg"), ("_rad", "rad"),
                     ("_us", "us"), ("_hz", "Hz"), ("_px", "px"), ("_m", "m"), ("_s", "s")]
BRACKET_UNIT = re.compile(r"\[(N m|rad/s|m\^2|rad\^2|mm|m|deg|rad|s|us|px|bytes|Hz)(?:\]| since )")
FIELD_LINE = re.compile(r"^\s*([\w.]+)\s+(\w+)\s*(?:\[[^;]*\])?\s*;")


def comment_units(path):
    """{(struct, field): (unit, whether the block is about that field alone)} from the comment
    blocks of one .lcm file. A block's unit goes to its
    floating-point fields, and to an integer field only when that is the block's one field."""
    units = {}
    blocks = []  # (struct, {units}, [(type, field)])
    struct = None
    in_comment = False
    with open(path, encoding="utf-8") as f:
        for line in f:
            stripped = line.strip()
            start = re.match(r"struct\s+(\w+)", stripped)
            field = FIELD_LINE.match(line)
            if start:
                struct, in_comment = start.group(1), False
            elif stripped.startswith("//"):
                if not in_comment:
                    blocks.append((struct, set(), []))
                in_comment = True
                blocks[-1][1].update(BRACKET_UNIT.findall(stripped))
            elif field and struct and blocks and blocks[-1][0] == struct and (in_comment or blocks[-1][2]):
                in_comment = False
                blocks[-1][2].append((field.group(1), field.group(2)))
            else:
                in_comment = False
                blocks.append((struct, set(), []))  # a blank line or a const ends the block
    for struct, block_units, fields in blocks:
        if len(block_units) != 1:
            continue
        for type_name, name in fields:
            if type_name in ("double", "float") or len(fields) == 1:
                units[(struct, name)] = (next(iter(block_units)), len(fields) == 1)
    return units


def parse_all(lcm_files):
    """[(package, struct name, fields)] of every struct in the files (in sorted file order), and
    their comment units ({(struct, field): ...}, comment_units)."""
    parsed, units = [], {}
    for path in sorted(lcm_files):
        package, structs = parse_lcm(path)
        parsed.extend((package, name, fields) for name, fields in structs)
        units.update(comment_units(path))
    return parsed, units


def unit_of(struct, field, units):
    comment_unit, own_comment = units.get((struct, field.name), ("", False))
    if own_comment:
        return comment_unit  # K_m [px]: the suffix names the mirror, the comment the unit
    for suffix, unit in NAME_SUFFIX_UNITS:
        if field.name.endswith(suffix):
            return unit
    if field.name == "utime":
        return "us"
    if field.type_name == "byte" and field.dims:
        return "bytes"
    return comment_unit


def emit_struct(package, name, fields, units):
    out = [f"inline void Flatten(const ::{package}::{name}& m, const std::string& prefix, FlatRow& row) {{"]
    for field in fields:
        unit = unit_of(name, field, units)
        if field.type_name == "byte" and field.dims:
            if len(field.dims) != 1:
                sys.exit(f"{name}.{field.name}: only one-dimensional byte arrays are flattened")
            out.append(f'  row.AddByteCount(prefix + "{field.name}", m.{field.name}.size());')
            continue
        indent = "  "
        path = f'prefix + "{field.name}"'
        access = f"m.{field.name}"
        for depth, dim in enumerate(field.dims):
            bound = dim if dim.isdigit() else f"static_cast<int64_t>(m.{dim})"
            out.append(f"{indent}for (int64_t i{depth} = 0; i{depth} < {bound}; ++i{depth}) {{")
            indent += "  "
            path += f' + "[" + std::to_string(i{depth}) + "]"'
            access += f"[i{depth}]"
        if field.type_name in PRIMITIVE_BYTES or field.type_name == "string":
            out.append(f'{indent}row.Add({path}, "{unit}", {access});')
        else:
            out.append(f'{indent}Flatten({access}, {path} + ".", row);')
        for depth in reversed(range(len(field.dims))):
            indent = indent[:-2]
            out.append(f"{indent}}}")
    out.append("}")
    return out


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    output, lcm_files = sys.argv[1], sys.argv[2:]
    parsed, units = parse_all(lcm_files)
    lines = [
        "// Generated by lcmtypes/gen_flatten.py from the .lcm files: do not edit.",
        "// Flatten(const T&, prefix, FlatRow&) appends every field of T as named cells with units;",
        "// see lcmtypes/flat_row.h.",
        "#pragma once",
        "",
        "#include <cstdint>",
        "#include <string>",
        "",
        '#include "lcmtypes/flat_row.h"',
        "",
    ]
    lines += [f"#include <{package}/{name}.hpp>" for package, name, _ in parsed]
    lines += ["", "namespace orbed {", "namespace flat {", ""]
    lines += [f"inline void Flatten(const ::{package}::{name}& m, const std::string& prefix, FlatRow& row);"
              for package, name, _ in parsed]
    for package, name, fields in parsed:
        lines.append("")
        lines += emit_struct(package, name, fields, units)
    lines += ["", "}  // namespace flat", "}  // namespace orbed", ""]
    with open(output, "w", encoding="utf-8") as f:
        f.write("\n".join(lines))


if __name__ == "__main__":
    main()
