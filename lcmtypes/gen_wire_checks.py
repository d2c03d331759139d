#!/usr/bin/env python3
"""Generates orbed/wire_checks.hpp: for every struct of the .lcm files, a function that walks its
LCM encoding with each array count bounded by the bytes left, so that a message can be refused
before LCM's generated decode (which resizes vectors to whatever count it reads) allocates.

usage: gen_wire_checks.py OUTPUT.hpp FILE.lcm...

The walk mirrors LCM's encoding: big-endian primitives, a string is an int32 length (counting its
terminating NUL) followed by that many bytes, nested structs are encoded without their fingerprint,
and an array's dimensions are constants or integer fields that precede it in the same struct.
The runtime half (WireReader) is lcmtypes/wire_reader.h.
"""

import re
import sys

# Encoded size of each LCM primitive, in bytes.
PRIMITIVE_BYTES = {
    "int8_t": 1, "byte": 1, "boolean": 1, "int16_t": 2, "int32_t": 4, "int64_t": 8,
    "float": 4, "double": 8,
}
INTEGER_TYPES = {"int8_t", "int16_t", "int32_t", "int64_t", "byte"}


def strip_comments(text):
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    return re.sub(r"//[^\n]*", " ", text)


class Field:
    def __init__(self, type_name, name, dims):
        self.type_name = type_name  # primitive, "string" or a struct name (without package)
        self.name = name
        self.dims = dims            # list of str: integer literals or names of earlier fields


def parse_lcm(path):
    """Returns (package, [(struct_name, [Field])]) of one .lcm file."""
    with open(path, encoding="utf-8") as f:
        text = strip_comments(f.read())
    package_match = re.search(r"\bpackage\s+([A-Za-z_][\w.]*)\s*;", text)
    package = package_match.group(1) if package_match else ""
    structs = []
    for match in re.finditer(r"\bstruct\s+(\w+)\s*\{(.*?)\}", text, flags=re.S):
        fields = []
        for statement in match.group(2).split(";"):
            statement = statement.strip()
            if not statement or statement.startswith("const "):
                continue
            decl = re.fullmatch(r"([\w.]+)\s+(\w+)\s*((?:\[\s*\w+\s*\]\s*)*)", statement)
            if not decl:
                sys.exit(f"{path}: cannot parse field '{statement}'")
            type_name = decl.group(1).split(".")[-1]
            dims = re.findall(r"\[\s*(\w+)\s*\]", decl.group(3))
            fields.append(Field(type_name, decl.group(2), dims))
        structs.append((match.group(1), fields))
    return package, structs


def emit_struct(package, name, fields, known_structs):
    out = [f"inline bool CheckBody(const ::{package}::{name}*, WireReader& r) {{"]
    declared = {}
    dimension_names = {d for f in fields for d in f.dims if not d.isdigit()}
    for field in fields:
        label = f'"{name}.{field.name}"'
        for dim in field.dims:
            if not dim.isdigit() and dim not in declared:
                sys.exit(f"{name}.{field.name}: dimension '{dim}' is not an earlier integer field")
        if field.dims:
            dims = ", ".join(d if d.isdigit() else f"n_{d}" for d in field.dims)
            if field.type_name in PRIMITIVE_BYTES:
                out.append(f"  if (!r.SkipArray({{{dims}}}, {PRIMITIVE_BYTES[field.type_name]}, {label})) "
                           "return false;")
                continue
            out.append("  {")
            out.append("    int64_t count = 0;")
            out.append(f"    if (!r.Count({{{dims}}}, &count, {label})) return false;")
            out.append("    for (int64_t i = 0; i < count; ++i) {")
            out.append("      " + element_check(package, field, label, known_structs, "      "))
            out.append("    }")
            out.append("  }")
            continue
        if field.name in dimension_names:
            if field.type_name not in INTEGER_TYPES:
                sys.exit(f"{name}.{field.name}: used as a dimension but is not an integer")
            out.append(f"  int64_t n_{field.name} = 0;")
            out.append(f"  if (!r.ReadInteger({PRIMITIVE_BYTES[field.type_name]}, &n_{field.name}, {label})) "
                       "return false;")
            declared[field.name] = True
            continue
        out.append("  " + element_check(package, field, label, known_structs, "  "))
    out.append("  return true;")
    out.append("}")
    return out


def element_check(package, field, label, known_structs, indent):
    if field.type_name in PRIMITIVE_BYTES:
        return f"if (!r.Skip({PRIMITIVE_BYTES[field.type_name]}, {label})) return false;"
    if field.type_name == "string":
        return f"if (!r.SkipString({label})) return false;"
    if field.type_name not in known_structs:
        sys.exit(f"{label}: unknown type '{field.type_name}'")
    return (f"if (!CheckBody(static_cast<const ::{package}::{field.type_name}*>(nullptr), r)) "
            "return false;")


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    output, lcm_files = sys.argv[1], sys.argv[2:]
    parsed = []
    for path in sorted(lcm_files):
        package, structs = parse_lcm(path)
        parsed.extend((package, name, fields) for name, fields in structs)
    known = {name for _, name, _ in parsed}
    lines = [
        "// Generated by lcmtypes/gen_wire_checks.py from the .lcm files: do not edit.",
        "// CheckBody(const T*, WireReader&) walks T's encoding (after the fingerprint) with every",
        "// count bounded by the bytes left; see lcmtypes/wire_reader.h and lcmtypes/bounded_decode.h.",
        "#pragma once",
        "",
        "#include <cstdint>",
        "",
        '#include "lcmtypes/wire_reader.h"',
        "",
    ]
    lines += [f"#include <{package}/{name}.hpp>" for package, name, _ in parsed]
    lines += ["", "namespace orbed {", "namespace wire {", ""]
    lines += [f"inline bool CheckBody(const ::{package}::{name}*, WireReader& r);" for package, name, _ in parsed]
    for package, name, fields in parsed:
        lines.append("")
        lines += emit_struct(package, name, fields, known)
    lines += ["", "}  // namespace wire", "}  // namespace orbed", ""]
    with open(output, "w", encoding="utf-8") as f:
        f.write("\n".join(lines))


if __name__ == "__main__":
    main()
