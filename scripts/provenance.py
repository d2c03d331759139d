#!/usr/bin/python3
"""provenance.py: the provenance record of an orbed run folder (RUN/provenance.json), and its check.

  provenance.py start RUN --kind KIND [--launch FILE] [--setting KEY=VALUE]... [--config FILE]...
                          [--parent DIR] -- COMMAND LINE...
      writes RUN/provenance.json: the project version, git commit and whether the tree was dirty,
      the command line, the settings (every seed among them) as they were in effect, the sim's rate,
      each configuration file with its SHA-256 (the launch file, the files it includes and every
      existing file its processes are given), this host's name and the hosts the launch file
      places processes on, and the start time.
  provenance.py finish RUN --exit-code N
      adds the end time, the exit code and the SHA-256 of every file the run left in RUN (a run
      folder inside RUN has its own record and is listed by name).
  provenance.py verify RUN [--bin DIR]
      recomputes what can be recomputed and says what differs: the outputs' hashes; the
      configuration files as the source tree has them now; for a study, its tables made again by
      orbed-study-tables and the analysis (python/orbed/study) from the run folders it lists (byte for
      byte); every run folder inside RUN in turn. Exit code 0 when nothing differs, 1 when something does, 2 on a usage error.

Written and read by scripts/orbed; the format is documented in docs/runs.md. Needs Python's standard
library and python3-yaml (Debian); verifying a study's tables also pandas, scipy and statsmodels.
"""
import argparse
import datetime
import filecmp
import hashlib
import json
import os
import re
import socket
import subprocess
import sys
import tempfile

import yaml

FORMAT = "orbed.provenance/1"
RECORD = "provenance.json"
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# The study's files that orbed-study-tables and the analysis (python/orbed/study) write; verify makes
# them again.
TABLE_FILES = ("alignment_trials.csv", "alignment_means.csv", "alignment_groups.csv", "landmark_validation.csv",
               "setup_joints.csv", "setup_times.csv", "setup_docking.csv", "setup_truth_joints.csv", "tables.json")


def now_utc():
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%S.%fZ")


def sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def git(*args):
    try:
        return subprocess.run(["git", "-C", ROOT, *args], check=True, capture_output=True,
                              text=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return None


def git_state():
    commit = git("rev-parse", "HEAD")
    if commit is None:
        return {"commit": None, "dirty": None, "changed": []}
    status = git("status", "--porcelain", "--untracked-files=no") or ""
    changed = [line[3:] for line in status.splitlines() if line.strip()]
    return {"commit": commit.strip(), "dirty": bool(changed), "changed": changed[:100]}


def project_version():
    with open(os.path.join(ROOT, "CMakeLists.txt")) as f:
        found = re.search(r"project\(\s*orbed\s+VERSION\s+([0-9.]+)", f.read())
    return found.group(1) if found else None


def relative(path):
    path = os.path.abspath(path)
    return os.path.relpath(path, ROOT) if path.startswith(ROOT + os.sep) else path


def expand(text):
    """A launch file's ${NAME} from the environment (as orbed-launch expands them)."""
    return re.sub(r"\$\{([A-Za-z_][A-Za-z0-9_]*)\}", lambda m: os.environ.get(m.group(1), ""), text)


def launch_chain(path, seen=None):
    """The launch file and every file it includes, each once, with their parsed documents."""
    seen = seen if seen is not None else {}
    path = os.path.abspath(path)
    if path in seen:
        return seen
    with open(path) as f:
        doc = yaml.safe_load(f) or {}
    seen[path] = doc
    for name in doc.get("include", []) or []:
        launch_chain(os.path.join(os.path.dirname(path), str(name)), seen)
    return seen


def launch_inputs(launch_file):
    """Configuration files (the launch chain and each existing file a process is given) and the
    hosts processes are placed on."""
    files, hosts = [], set()
    for path, doc in launch_chain(launch_file).items():
        files.append(path)
        hosts.update(str(h) for h in (doc.get("placement") or {}).values())
        for group in doc.get("groups", []) or []:
            if group.get("host"):
                hosts.add(str(group["host"]))
            for proc in group.get("processes", []) or []:
                if proc.get("host"):
                    hosts.add(str(proc["host"]))
                for arg in proc.get("args", []) or []:
                    value = expand(str(arg))
                    if "/" in value and os.path.isfile(value):
                        files.append(os.path.abspath(value))
    return files, sorted(hosts)


def write_record(run, record):
    tmp = os.path.join(run, f".{RECORD}.tmp")
    with open(tmp, "w") as f:
        json.dump(record, f, indent=2)
        f.write("\n")
    os.replace(tmp, os.path.join(run, RECORD))


def inside(name, folder_only=False):
    """Whether `name` stays inside the folder it is relative to (a run's record names no other)."""
    if not isinstance(name, str) or not name or os.path.isabs(name):
        return False
    parts = name.split("/")
    if folder_only and len(parts) != 1:
        return False
    return all(p not in ("", ".", "..") for p in parts)


def read_record(run):
    """The record of RUN; ValueError naming what is wrong when it is not one this script wrote."""
    path = os.path.join(run, RECORD)
    try:
        with open(path) as f:
            record = json.load(f)
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise ValueError(f"{path}: cannot be read as JSON ({e})")
    if not isinstance(record, dict) or record.get("format") != FORMAT:
        raise ValueError(f"{path}: not an orbed provenance record ({FORMAT})")
    expected = {"run": str, "kind": str, "git": dict, "started_utc": str, "config_files": list,
                "outputs": list}
    for key, kind in expected.items():
        if not isinstance(record.get(key), kind):
            raise ValueError(f"{path}: {key}: expected a {kind.__name__}")
    for out in record["outputs"]:
        if not isinstance(out, dict) or not inside(out.get("path")) or not isinstance(out.get("sha256"), str):
            raise ValueError(f"{path}: outputs: expected {{path inside the run folder, sha256}}, got {out!r}")
    for cfg in record["config_files"]:
        if not isinstance(cfg, dict) or not isinstance(cfg.get("path"), str) or not isinstance(cfg.get("sha256"), str):
            raise ValueError(f"{path}: config_files: expected {{path, sha256}}, got {cfg!r}")
    runs = record.get("runs", [])
    if not isinstance(runs, list) or not all(inside(r, folder_only=True) for r in runs):
        raise ValueError(f"{path}: runs: expected names of folders inside the run, got {runs!r}")
    return record


def parse_setting(text):
    key, sep, value = text.partition("=")
    if not sep or not key:
        raise argparse.ArgumentTypeError(f"expected KEY=VALUE, got '{text}'")
    return key, value


def cmd_start(args):
    configs, hosts = [], []
    if args.launch:
        configs, hosts = launch_inputs(args.launch)
    configs += [os.path.abspath(c) for c in args.config]
    unique = list(dict.fromkeys(configs))
    record = {
        "format": FORMAT,
        "run": os.path.basename(os.path.abspath(args.run)),
        "kind": args.kind,
        "orbed_version": project_version(),
        "git": git_state(),
        "command_line": args.command_line,
        "started_utc": now_utc(),
        "ended_utc": None,
        "exit_code": None,
        "host": socket.gethostname(),
        "placed_on_hosts": hosts,
        "settings": dict(args.setting),
        "arguments": {},
        "overrides": {"settings": {}, "from": {}},
        "config_files": [{"path": relative(c), "sha256": sha256(c)} for c in unique],
        "outputs": [],
    }
    # What scripts/orbed wrote into the folder before the start: the launch's arguments as
    # orbed-launch resolved them, and the settings given with --config / --set (scripts/settings.py).
    arguments = os.path.join(args.run, "launch_arguments.json")
    if os.path.isfile(arguments):
        with open(arguments) as f:
            record["arguments"] = {k: v["value"] for k, v in json.load(f).items()}
        # A file an argument names (an overlay, a run to resume) is an input too.
        hashed = {c["path"] for c in record["config_files"]}
        for value in record["arguments"].values():
            if value and os.path.isfile(value) and relative(value) not in hashed:
                record["config_files"].append({"path": relative(value), "sha256": sha256(value)})
                hashed.add(relative(value))
    overrides = os.path.join(args.run, "settings", "settings.json")
    if os.path.isfile(overrides):
        with open(overrides) as f:
            record["overrides"] = json.load(f)
    if args.parent:
        record["part_of"] = os.path.basename(os.path.abspath(args.parent))
    write_record(args.run, record)


def outputs(run):
    """Every file in RUN but the record, with its SHA-256; run folders inside it by name."""
    files, runs = [], []
    for name in sorted(os.listdir(run)):
        path = os.path.join(run, name)
        if name == RECORD or name.startswith("."):
            continue
        if os.path.isdir(path):
            if os.path.isfile(os.path.join(path, RECORD)):
                runs.append(name)
            else:
                for sub, _, names in sorted(os.walk(path)):
                    for n in sorted(names):
                        p = os.path.join(sub, n)
                        files.append({"path": os.path.relpath(p, run), "sha256": sha256(p),
                                      "bytes": os.path.getsize(p)})
        elif os.path.isfile(path):
            files.append({"path": name, "sha256": sha256(path), "bytes": os.path.getsize(path)})
    return files, runs


def cmd_finish(args):
    record = read_record(args.run)
    record["ended_utc"] = now_utc()
    record["exit_code"] = args.exit_code
    record["outputs"], record["runs"] = outputs(args.run)
    write_record(args.run, record)


def verify(run, bin_dir, depth=0):
    """Prints what differs in RUN (and the run folders in it); returns the number of differences."""
    pad = "  " * depth
    try:
        record = read_record(run)
    except (OSError, ValueError) as e:
        print(f"{pad}{run}: {e}")
        return 1
    differ = 0
    print(f"{pad}{record['run']} ({record['kind']}; commit {str(record['git'].get('commit') or '?')[:12]}"
          f"{' dirty' if record['git'].get('dirty') else ''}; started {record['started_utc']};"
          f" exit code {record.get('exit_code')})")
    if record.get("ended_utc") is None:
        print(f"{pad}  not finished: the run was stopped, or is still going")
        differ += 1
    for out in record.get("outputs", []):
        path = os.path.join(run, out["path"])
        if not os.path.isfile(path):
            print(f"{pad}  missing: {out['path']}")
            differ += 1
        elif sha256(path) != out["sha256"]:
            print(f"{pad}  changed since the run: {out['path']}")
            differ += 1
    checked = len(record.get("outputs", []))
    drifted = []
    for cfg in record["config_files"]:
        path = cfg["path"] if os.path.isabs(cfg["path"]) else os.path.join(ROOT, cfg["path"])
        if not os.path.isfile(path) or sha256(path) != cfg["sha256"]:
            drifted.append(cfg["path"])
    if drifted:
        # Not a fault of the run: the tree moved on. Said, not counted.
        print(f"{pad}  configuration changed in the source tree since the run: {', '.join(drifted)}")
    head = git("rev-parse", "HEAD")
    if head and record["git"].get("commit") and head.strip() != record["git"]["commit"]:
        print(f"{pad}  the source tree is now at {head.strip()[:12]}, not the run's commit")
    if record["kind"] == "study" and os.path.isfile(os.path.join(run, "tables_args.json")):
        differ += verify_tables(run, bin_dir, pad)
    print(f"{pad}  {checked} output hashes checked, {len(record['config_files'])} configuration files")
    for name in record.get("runs", []):
        differ += verify(os.path.join(run, name), bin_dir, depth + 1)
    return differ


def verify_tables(run, bin_dir, pad):
    """The study's tables made again from its run folders, compared byte for byte."""
    with open(os.path.join(run, "tables_args.json")) as f:
        tables_args = json.load(f)
    differ = 0
    with tempfile.TemporaryDirectory() as tmp:
        # tables.json names the record beside it: the same name in the folder made again.
        with open(os.path.join(tmp, RECORD), "w") as f:
            f.write("{}")
        argv = [os.path.join(bin_dir, "orbed-study-tables"), "--out", tmp]
        for arg in tables_args:
            argv.append(os.path.join(run, arg[len("run:"):]) if arg.startswith("run:") else arg)
        made = subprocess.run(argv, capture_output=True, text=True)
        if made.returncode != 0:
            print(f"{pad}  the tables could not be made again: {made.stderr.strip()}")
            return 1
        # The tables themselves: the study's analysis, as `scripts/orbed study` runs it.
        sys.path.insert(0, os.path.join(ROOT, "python"))
        from orbed.study import analysis  # scipy, statsmodels: only for a study
        analysis.write(tmp)
        same = 0
        for name in TABLE_FILES:
            ours, again = os.path.join(run, name), os.path.join(tmp, name)
            if os.path.isfile(ours) != os.path.isfile(again):
                print(f"{pad}  {name}: {'only in the run' if os.path.isfile(ours) else 'not in the run'}")
                differ += 1
            elif os.path.isfile(ours):
                if filecmp.cmp(ours, again, shallow=False):
                    same += 1
                else:
                    print(f"{pad}  {name}: differs from the tables made again from the runs")
                    differ += 1
        print(f"{pad}  tables made again from the run folders: {same} files identical")
    return differ


def main(argv):
    parser = argparse.ArgumentParser(prog="provenance.py", description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="verb", required=True)
    start = sub.add_parser("start", help="write RUN/provenance.json at a run's start")
    start.add_argument("run")
    start.add_argument("--kind", required=True)
    start.add_argument("--launch", help="the launch file (its chain and inputs are hashed)")
    start.add_argument("--setting", action="append", type=parse_setting, default=[])
    start.add_argument("--config", action="append", default=[])
    start.add_argument("--parent", help="the run folder this run is part of")
    finish = sub.add_parser("finish", help="add the end, the exit code and the outputs' hashes")
    finish.add_argument("run")
    finish.add_argument("--exit-code", type=int, required=True)
    check = sub.add_parser("verify", help="recompute what can be recomputed and say what differs")
    check.add_argument("run")
    check.add_argument("--bin", default=os.path.join(os.environ.get("ORBED_BUILD_DIR",
                                                                    os.path.join(ROOT, "build")), "bin"))
    # Everything after "--" is the command line being recorded, taken as it is.
    command_line = []
    if "--" in argv:
        command_line = argv[argv.index("--") + 1:]
        argv = argv[:argv.index("--")]
    args = parser.parse_args(argv)
    args.command_line = command_line
    if args.verb == "start":
        cmd_start(args)
    elif args.verb == "finish":
        cmd_finish(args)
    else:
        if not os.path.isdir(args.run):
            parser.error(f"no run folder {args.run}")
        differ = verify(args.run, args.bin)
        print(f"verify: {'nothing differs' if differ == 0 else f'{differ} difference(s)'}")
        return 0 if differ == 0 else 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
