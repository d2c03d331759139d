#!/usr/bin/env python3
"""Generates orbed/to_json.hpp: for every struct of the .lcm files, its JSON Schema (as text) and a
function that writes a decoded message as JSON in that shape, for `orbed-log export --mcap` (the
runtime half is lcmtypes/lcm_json.h).

usage: gen_json.py OUTPUT.hpp FILE.lcm...

The JSON of a message is an object with one member per field, in field order:
  - boolean: true/false; integers: exact decimal (int64 too: beyond 2^53 a reader that parses
    numbers as doubles, as JavaScript and Foxglove do, gets the nearest double; the text is exact);
  - double, float: the shortest decimal that reads back to the same value; NaN and infinities as
    null (JSON has no NaN);
  - string: text (bytes that are not UTF-8 become U+FFFD when the document is written);
  - a byte array: one base64 string (contentEncoding base64, which Foxglove decodes to bytes);
  - a nested struct: an object; an array: a JSON array, a multi-dimensional one flattened in
    row-major order (Foxglove reads no arrays of arrays), its shape said in the schema's description.
The schemas use only what Foxglove's JSON Schema reader accepts (one "type" per property; arrays of
one item type), with "required" and "additionalProperties": false, and units (gen_flatten.py's
rules) in "description". The .lcm parser is gen_wire_checks.py's.
"""

import json
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
from gen_flatten import parse_all, unit_of  # noqa: E402 (after the line above)

INTEGER_RANGES = {"int8_t": (-128, 127), "int16_t": (-32768, 32767), "int32_t": (-2 ** 31, 2 ** 31 - 1),
                  "byte": (0, 255)}


def element_schema(field, structs, units_of):
    t = field.type_name
    if t == "boolean":
        return {"type": "boolean"}
    if t in INTEGER_RANGES:
        low, high = INTEGER_RANGES[t]
        return {"type": "integer", "minimum": low, "maximum": high}
    if t == "int64_t":
        return {"type": "integer"}
    if t in ("double", "float"):
        return {"type": "number"}
    if t == "string":
        return {"type": "string"}
    return struct_schema(t, structs, units_of)


def struct_schema(name, structs, units_of):
    package, fields = structs[name]
    properties = {}
    for field in fields:
        unit = unit_of(name, field, units_of)
        if field.type_name == "byte" and field.dims:
            if len(field.dims) != 1:
                sys.exit(f"{name}.{field.name}: only one-dimensional byte arrays are written")
            properties[field.name] = {"type": "string", "contentEncoding": "base64",
                                      "description": f"bytes, base64; length {field.dims[0]}"}
            continue
        schema = element_schema(field, structs, units_of)
        notes = []
        if unit and field.type_name in ("double", "float", "int64_t", "int32_t", "int16_t", "int8_t"):
            notes.append(f"[{unit}]")
        if field.type_name in ("double", "float"):
            notes.append("null when not finite")
        if notes:
            schema = dict(schema, description="; ".join(notes))
        if field.dims:
            shape = " x ".join(field.dims)
            schema = {"type": "array", "items": schema,
                      "description": f"{shape}, row-major" if len(field.dims) > 1 else f"length {shape}"}
            if all(d.isdigit() for d in field.dims):
                n = 1
                for d in field.dims:
                    n *= int(d)
                schema["minItems"] = schema["maxItems"] = n
        properties[field.name] = schema
    return {"title": f"{package}.{name}", "type": "object", "properties": properties,
            "required": [f.name for f in fields], "additionalProperties": False}


def emit_struct(package, name, fields):
    out = [f"inline void ToJson(const ::{package}::{name}& m, nlohmann::ordered_json& j) {{",
           "  j = nlohmann::ordered_json::object();"]
    for field in fields:
        t = field.type_name
        if t == "byte" and field.dims:
            out.append(f'  j["{field.name}"] = JsonBase64(m.{field.name});')
            continue
        access = f"m.{field.name}"
        if not field.dims:
            target = f'j["{field.name}"]'
        else:
            out.append("  {")
            out.append(f'    nlohmann::ordered_json& a = j["{field.name}"] = nlohmann::ordered_json::array();')
            target = None
        indent = "    "
        for depth, dim in enumerate(field.dims):
            bound = dim if dim.isdigit() else f"static_cast<int64_t>(m.{dim})"
            out.append(f"{indent}for (int64_t i{depth} = 0; i{depth} < {bound}; ++i{depth}) {{")
            indent += "  "
            access += f"[i{depth}]"
        if t == "boolean":
            value = f"{access} != 0"
        elif t in INTEGER_RANGES or t == "int64_t":
            value = f"static_cast<int64_t>({access})"
        elif t in ("double", "float"):
            value = f"JsonDouble({access})"
        elif t == "string":
            value = access
        else:
            value = None
        if target is not None:
            if value is None:
                out.append(f"  ToJson({access}, {target});")
            else:
                out.append(f"  {target} = {value};")
            continue
        if value is None:
            out.append(f"{indent}ToJson({access}, a.emplace_back());")
        else:
            out.append(f"{indent}a.push_back({value});")
        for depth in reversed(range(len(field.dims))):
            indent = indent[:-2]
            out.append(f"{indent}}}")
        out.append("  }")
    out.append("}")
    return out


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    output, lcm_files = sys.argv[1], sys.argv[2:]
    parsed, units = parse_all(lcm_files)
    structs = {name: (package, fields) for package, name, fields in parsed}
    lines = [
        "// Generated by lcmtypes/gen_json.py from the .lcm files: do not edit.",
        "// ToJson(const T&, ordered_json&) writes every field of T as JSON; JsonSchemaText(const T*) is",
        "// the JSON Schema of that JSON. See lcmtypes/gen_json.py and lcmtypes/lcm_json.h.",
        "#pragma once",
        "",
        "#include <cstdint>",
        "",
        "#include <nlohmann/json.hpp>",
        "",
        '#include "lcmtypes/lcm_json.h"',
        "",
    ]
    lines += [f"#include <{package}/{name}.hpp>" for package, name, _ in parsed]
    lines += ["", "namespace orbed {", "namespace lcm_json {", ""]
    lines += [f"inline void ToJson(const ::{package}::{name}& m, nlohmann::ordered_json& j);"
              for package, name, _ in parsed]
    for package, name, fields in parsed:
        schema = json.dumps(struct_schema(name, structs, units), separators=(",", ":"))
        lines.append("")
        lines.append(f"inline const char* JsonSchemaText(const ::{package}::{name}*) {{")
        lines.append(f'  return R"orbed({schema})orbed";')
        lines.append("}")
        lines += emit_struct(package, name, fields)
    lines += ["", "}  // namespace lcm_json", "}  // namespace orbed", ""]
    with open(output, "w", encoding="utf-8") as f:
        f.write("\n".join(lines))


if __name__ == "__main__":
    main()
