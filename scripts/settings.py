#!/usr/bin/python3
"""settings.py: a run's own settings, from --config FILE and --set KEY=VALUE, as the files its
processes read.

  settings.py OUT [--config FILE]... [--set KEY=VALUE]...

The settings are the keys of orbed's configuration files, dotted: user.*, slam.*,
head_trajectory.* and hmd.* (hmd_emulator/config/*.yaml, read by orbed-hmd and orbed-user-study)
and assistant.* (procs/assistant/assistant.yaml, read by orbed-assistant). Each --config FILE is a
YAML file of such sections; the --set values come after them, in order, and each VALUE is read as
YAML (0.03 is a number, [1, 2] a list, abc a string). Writes OUT/hmd.yaml and OUT/assistant.yaml
(only those with a key), each key followed by a comment naming where it came from, and
OUT/settings.json (the merged settings, for the provenance record); prints one NAME=VALUE line per
launch argument that passes them on (hmd_config=..., assistant_config=...). A section that is none
of these, or a FILE that is not a YAML mapping, is refused (exit code 2) before anything is written;
the processes' own checked readers then check every key and value (scripts/orbed runs them with
--check-config before a run starts).
"""
import argparse
import json
import math
import os
import sys

import yaml

# Section -> (the overlay file it goes into, the launch argument naming that file).
SECTIONS = {
    "user": ("hmd.yaml", "hmd_config"),
    "slam": ("hmd.yaml", "hmd_config"),
    "head_trajectory": ("hmd.yaml", "hmd_config"),
    "hmd": ("hmd.yaml", "hmd_config"),
    "assistant": ("assistant.yaml", "assistant_config"),
}


class SettingsError(Exception):
    pass


def plain(value):
    """Whether `value` is what a configuration key can hold: a string, a finite number, a bool, or a
    list of those or of mappings of those (a walk's waypoints); not a date, binary, a null or a NaN,
    which YAML can also spell."""
    if isinstance(value, list):
        return all(plain(v) for v in value)
    if isinstance(value, dict):
        return all(isinstance(k, str) and plain(v) for k, v in value.items())
    if isinstance(value, float):
        return math.isfinite(value)
    return isinstance(value, (str, int, bool))


def merge(into, origin_into, key, value, origin):
    """Puts `value` at the dotted `key` of `into`; mappings merge key by key, anything else replaces."""
    if isinstance(value, dict):
        for k, v in value.items():
            merge(into, origin_into, f"{key}.{k}" if key else str(k), v, origin)
        return
    parts = key.split(".")
    if parts[0] not in SECTIONS:
        raise SettingsError(
            f"{origin}: {key}: '{parts[0]}' is not a section of orbed's configuration; the settings are "
            f"{', '.join(s + '.*' for s in SECTIONS)} (hmd_emulator/config/*.yaml, procs/assistant/assistant.yaml)")
    if len(parts) < 2 or any(not p for p in parts):
        raise SettingsError(f"{origin}: {key}: expected a key inside the section, e.g. {parts[0]}.seed")
    if not plain(value):
        raise SettingsError(f"{origin}: {key}: expected a string, a finite number, true/false or a list "
                            f"of those (or of mappings of those), got {value!r}")
    node = into
    for p in parts[:-1]:
        if not isinstance(node.get(p), dict):
            node[p] = {}
        node = node[p]
    node[parts[-1]] = value
    origin_into[key] = origin


def read_config(path):
    try:
        with open(path) as f:
            doc = yaml.safe_load(f)
    except OSError as e:
        raise SettingsError(f"--config {path}: {e.strerror}")
    except (yaml.YAMLError, UnicodeDecodeError) as e:
        raise SettingsError(f"--config {path}: not YAML: {e}")
    if doc is None:
        return {}
    if not isinstance(doc, dict):
        raise SettingsError(f"--config {path}: expected a mapping of sections ({', '.join(SECTIONS)})")
    return doc


def parse_set(text):
    key, sep, value = text.partition("=")
    if not sep or not key.strip():
        raise SettingsError(f"--set {text}: expected KEY=VALUE, e.g. user.direct_view.depth_bias_fraction_std=0.03")
    try:
        return key.strip(), yaml.safe_load(value) if value.strip() else ""
    except yaml.YAMLError as e:
        raise SettingsError(f"--set {text}: the value is not YAML: {e}")


def settings(configs, sets):
    """The merged settings and, per dotted key, where it came from."""
    merged, origins = {}, {}
    for path in configs:
        merge(merged, origins, "", read_config(path), f"--config {path}")
    for text in sets:
        key, value = parse_set(text)
        merge(merged, origins, key, value, f"--set {text}")
    return merged, origins


def leaves(node, prefix=""):
    for k, v in node.items():
        key = f"{prefix}.{k}" if prefix else str(k)
        if isinstance(v, dict):
            yield from leaves(v, key)
        else:
            yield key, v


def overlay_text(sections, origins):
    """YAML of the sections, each leaf on its own line with a comment naming its origin."""
    lines = ["# Written by scripts/settings.py for this run: the settings given to scripts/orbed."]

    def emit(node, depth, prefix):
        for k, v in node.items():
            key = f"{prefix}.{k}" if prefix else str(k)
            pad = "  " * depth
            if isinstance(v, dict):
                lines.append(f"{pad}{k}:")
                emit(v, depth + 1, key)
            else:
                value = json.dumps(v)  # JSON is YAML: lists, numbers and quoted strings
                lines.append(f"{pad}{k}: {value}  # {origins.get(key, '')}")

    emit(sections, 0, "")
    return "\n".join(lines) + "\n"


def main(argv):
    parser = argparse.ArgumentParser(prog="settings.py", description=__doc__.split("\n")[0])
    parser.add_argument("out")
    parser.add_argument("--config", action="append", default=[])
    parser.add_argument("--set", action="append", default=[], dest="sets")
    args = parser.parse_args(argv)
    try:
        merged, origins = settings(args.config, args.sets)
    except SettingsError as e:
        print(f"settings: {e}", file=sys.stderr)
        return 2
    files = {}
    for section, value in merged.items():
        name, _ = SECTIONS[section]
        files.setdefault(name, {})[section] = value
    # Every text first, then the files: nothing is written for settings that are refused.
    texts = {name: overlay_text(sections, origins) for name, sections in files.items()}
    texts["settings.json"] = json.dumps({"settings": dict(leaves(merged)), "from": origins}, indent=2) + "\n"
    os.makedirs(args.out, exist_ok=True)
    for name, text in texts.items():
        with open(os.path.join(args.out, name), "w") as f:
            f.write(text)
    for name in files:
        argument = next(a for n, a in SECTIONS.values() if n == name)
        print(f"{argument}={os.path.abspath(os.path.join(args.out, name))}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
