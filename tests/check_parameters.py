#!/usr/bin/python3
"""Checks that docs/parameters.md documents every leaf key of the shipped model configs.

Usage: /usr/bin/python3 tests/check_parameters.py REPO_ROOT

For each YAML file in FILES, docs/parameters.md has a section whose `## ` heading names the file in
backticks. In that section every leaf key path of the file must appear exactly once, either in the
first column of the parameter table (as `path`) or in the section's paragraph starting with
"Not model parameters:" (as `path`, outside parentheses). Paths listed there must exist in the
file. For table rows, the second column's first backticked value must equal the shipped value and
the fourth column (the source) must be one of SOURCE_CLASSES.

Leaf paths: mapping keys joined by '.'; a list of mappings contributes `key[].sub` for every key
`sub` of its items (its value: the list of the items' values); any other value (a scalar, a list
of scalars or lists) is a leaf.

Reads YAML with PyYAML (Debian's python3-yaml, for /usr/bin/python3). Exit 0: documented; 1: a discrepancy (each printed); 2: usage or unreadable input.
"""

import os
import re
import sys

import yaml  # PyYAML: Debian's python3-yaml, which `scripts/orbed setup` installs

FILES = [
    "hmd_emulator/config/user.yaml",
    "hmd_emulator/config/slam.yaml",
    "hmd_emulator/config/hmd.yaml",
    "hmd_emulator/config/viraal_walk.yaml",
    "hmd_emulator/config/walk_loop.yaml",
    "experiments/viraal/viraal.yaml",
    "procs/assistant/assistant.yaml",
]
DOC = "docs/parameters.md"
SOURCE_CLASSES = ("paper", "literature", "literature (as stated, not checked)", "fitted", "choice")
NOT_MODEL_PREFIX = "Not model parameters:"


# ---- Leaf paths ---------------------------------------------------------------------------------


def leaf_paths(node, prefix=""):
    """{path: value} of every leaf (see the module comment for the notation)."""
    out = {}
    if isinstance(node, dict):
        for key, value in node.items():
            path = f"{prefix}.{key}" if prefix else str(key)
            if isinstance(value, dict) and value:
                out.update(leaf_paths(value, path))
            elif isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
                keys = []
                for item in value:
                    keys += [k for k in item if k not in keys]
                for k in keys:
                    sub = [item.get(k) for item in value]
                    if any(isinstance(v, dict) for v in sub):
                        for item in value:  # nested mappings: their leaves, item by item
                            for p, v in leaf_paths(item.get(k), f"{path}[].{k}").items():
                                out.setdefault(p, []).append(v)
                    else:
                        out[f"{path}[].{k}"] = sub
            else:
                out[path] = value
    elif prefix:
        out[prefix] = node
    return out


def load_config(path, name):
    with open(path, encoding="utf-8") as f:
        return leaf_paths(yaml.safe_load(f))


def parse_value(text):
    return yaml.safe_load(text)


# ---- docs/parameters.md -------------------------------------------------------------------------

_BACKTICKED = re.compile(r"`([^`]+)`")


def split_row(line):
    cells = line.strip().strip("|").split("|")
    return [c.strip() for c in cells]


def read_doc(path):
    """{yaml file: {"table": [(line, path, value text, source)], "not_model": [(line, path)]}}

    The "Not model parameters:" entry is a paragraph (up to a blank line, heading or table); its
    paths are the backticked words outside parentheses, so the parentheses may explain them."""
    sections = {}
    current = None
    not_model = None  # (first line number, text) of a "Not model parameters:" paragraph being read
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            if not_model is not None:
                if line.strip() and not line.startswith(("#", "|")):
                    not_model[1].append(line)
                    continue
                current["not_model"] += [(not_model[0], p) for p in _not_model_paths("".join(not_model[1]))]
                not_model = None
            if line.startswith("#"):
                current = None
                if line.startswith("## "):
                    named = [t for t in _BACKTICKED.findall(line) if t in FILES]
                    if named:
                        current = sections.setdefault(named[0], {"table": [], "not_model": [], "headings": 0})
                        current["headings"] += 1
                continue
            if current is None:
                continue
            if line.startswith(NOT_MODEL_PREFIX):
                not_model = (number, [line])
            elif line.lstrip().startswith("|"):
                cells = split_row(line)
                if all(re.fullmatch(r":?-+:?", c) for c in cells if c) or not cells[0].startswith("`"):
                    continue  # separator or header row
                paths = _BACKTICKED.findall(cells[0])
                value = _BACKTICKED.findall(cells[1]) if len(cells) > 1 else []
                source = cells[3] if len(cells) > 3 else ""
                for p in paths:
                    current["table"].append((number, p, value[0] if value else None, source))
    if not_model is not None:
        current["not_model"] += [(not_model[0], p) for p in _not_model_paths("".join(not_model[1]))]
    return sections


def _not_model_paths(paragraph):
    """The `paths` of a "Not model parameters:" paragraph: backticked text outside parentheses."""
    outside, depth = [], 0
    for ch in paragraph:
        if ch == "(":
            depth += 1
        elif ch == ")":
            depth = max(0, depth - 1)
        elif depth == 0:
            outside.append(ch)
    return _BACKTICKED.findall("".join(outside))


def main(argv):
    if len(argv) != 2:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    root = argv[1]
    doc_path = os.path.join(root, DOC)
    problems = []
    try:
        sections = read_doc(doc_path)
    except OSError as e:
        print(f"check_parameters: {e}", file=sys.stderr)
        return 2
    total = 0
    for name in FILES:
        try:
            leaves = load_config(os.path.join(root, name), name)
        except (OSError, yaml.YAMLError) as e:
            print(f"check_parameters: {e}", file=sys.stderr)
            return 2
        total += len(leaves)
        section = sections.get(name)
        if section is None:
            problems.append(f"{DOC}: no '## `{name}`' section")
            continue
        if section["headings"] > 1:
            problems.append(f"{DOC}: {section['headings']} sections for `{name}`; expected one")
        seen = {}
        for number, path in [(n, p) for n, p, _, _ in section["table"]] + section["not_model"]:
            if path in seen:
                problems.append(f"{DOC}:{number}: `{path}` listed again (first at line {seen[path]})")
            seen.setdefault(path, number)
            if path not in leaves:
                problems.append(f"{DOC}:{number}: `{path}` is listed for {name} but is no leaf key there")
        for path in leaves:
            if path not in seen:
                problems.append(f"{name}: `{path}` is not listed in {DOC} (table or '{NOT_MODEL_PREFIX}' line)")
        for number, path, value_text, source in section["table"]:
            if source not in SOURCE_CLASSES:
                problems.append(f"{DOC}:{number}: `{path}`: source {source!r} is not one of {', '.join(SOURCE_CLASSES)}")
            if path not in leaves:
                continue
            if value_text is None:
                problems.append(f"{DOC}:{number}: `{path}`: no `value` in the second column")
                continue
            try:
                documented = parse_value(value_text)
            except Exception as e:  # a malformed value is a documentation error, reported as such
                problems.append(f"{DOC}:{number}: `{path}`: cannot read value `{value_text}`: {e}")
                continue
            if documented != leaves[path]:
                problems.append(f"{DOC}:{number}: `{path}`: documented `{value_text}`, {name} ships {leaves[path]!r}")
    for name in sections:
        if name not in FILES:
            problems.append(f"{DOC}: section for unknown file {name}")
    if problems:
        for p in problems:
            print(p)
        print(f"check_parameters: {len(problems)} problem(s)")
        return 1
    print(f"check_parameters: {total} leaf keys in {len(FILES)} files documented in {DOC} "
          "(YAML read by PyYAML)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
