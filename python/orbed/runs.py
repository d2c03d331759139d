"""orbed.runs: run folders (docs/runs.md) in Python, and `scripts/orbed run|study|sweep` started from it.

    run = orbed.runs.load("logs/study-20261204T181915Z-b81KfZ")
    run.provenance["git"]["commit"]; run.tables["table1"]; run.csv["setup_joints"]  # a DataFrame
    folder = orbed.runs.run("study", "--users", "1", "--trials", "1")               # waits; the folder

A folder's JSON files are read as dicts (provenance.json, results.json, setup_results.json,
tables.json, manifest.json, launch_arguments.json, tables_args.json), its CSV files as DataFrames by
stem, its logs listed (read them with orbed.log), and the run folders inside it (a study's users,
named in its provenance record) loaded the same way on demand (Run.runs()).
"""
import glob
import json
import os
import subprocess

import pandas as pd

from orbed import types

JSON_FILES = ("provenance", "results", "setup_results", "tables", "manifest", "launch_arguments", "tables_args")
VERBS = ("run", "study", "sweep")


class Run:
    """One run folder, read when made (see the module doc); a missing file is None / absent."""

    def __init__(self, path):
        if not os.path.isdir(path):
            raise FileNotFoundError(f"{path}: not a run folder")
        self.path = path
        self.name = os.path.basename(os.path.normpath(path))
        for stem in JSON_FILES:
            file = os.path.join(path, stem + ".json")
            setattr(self, stem, _read_json(file) if os.path.isfile(file) else None)
        self.csv = {os.path.splitext(os.path.basename(f))[0]: pd.read_csv(f)
                    for f in sorted(glob.glob(os.path.join(path, "*.csv")))}
        self.logs = sorted(glob.glob(os.path.join(path, "*.lcmlog")))

    @property
    def kind(self):
        return (self.provenance or {}).get("kind")

    def runs(self):
        """The run folders inside this one (a study's users), by name."""
        names = list((self.provenance or {}).get("runs") or [])  # provenance.py: the names
        if not names:
            names = sorted(os.path.basename(os.path.dirname(p))
                           for p in glob.glob(os.path.join(self.path, "*", "provenance.json")))
        return {n: Run(os.path.join(self.path, n)) for n in names if n and os.path.isdir(os.path.join(self.path, n))}

    def __repr__(self):
        return f"Run({self.path!r}, kind={self.kind!r})"


def _read_json(path):
    with open(path, encoding="utf-8") as f:
        return json.load(f)


def load(path):
    """The run folder at `path`."""
    return Run(path)


def logs_dir():
    """Where scripts/orbed makes run folders: $ORBED_LOGS_DIR, else <repo>/logs."""
    return os.environ.get("ORBED_LOGS_DIR") or os.path.join(types.REPO, "logs")


class Started:
    """A `scripts/orbed VERB ...` started by start(); wait() returns its run folder."""

    def __init__(self, verb, args, env, output):
        self.verb, self.args = verb, list(args)
        self.logs = env.get("ORBED_LOGS_DIR") or logs_dir()
        self.before = set(os.listdir(self.logs)) if os.path.isdir(self.logs) else set()
        self.process = subprocess.Popen([os.path.join(types.REPO, "scripts", "orbed"), verb, *self.args],
                                        env=env, stdout=output, stderr=subprocess.STDOUT if output else None)

    def wait(self, timeout_s=None, check=True):
        """Waits for the command; its run folder (the one it made in the logs folder, whose provenance
        record names this command line). check: raise CalledProcessError on a non-zero exit."""
        code = self.process.wait(timeout_s)
        if check and code != 0:
            raise subprocess.CalledProcessError(code, ["scripts/orbed", self.verb, *self.args])
        made = []
        for name in sorted(set(os.listdir(self.logs)) - self.before):
            record = os.path.join(self.logs, name, "provenance.json")
            if os.path.isfile(record) and _read_json(record).get("command_line", [])[-len(self.args) - 1:] == \
                    [self.verb, *self.args]:
                made.append(os.path.join(self.logs, name))
        if len(made) != 1:
            raise RuntimeError(f"scripts/orbed {self.verb}: {len(made)} new run folders in {self.logs} "
                               f"record this command line: {made}")
        return made[0]


def start(verb, *args, env=None, output=None):
    """Starts `scripts/orbed VERB ARGS...` (verb: run, study or sweep) without waiting. env: the
    environment (default this one); output: where its output goes (default this process's). The
    run gets a network namespace of its own, as from a shell, also when this process is inside
    one (`scripts/orbed join`, a test's namespace): it never shares a bus with what runs here."""
    if verb not in VERBS:
        raise ValueError(f"verb {verb!r}: one of {VERBS}")
    env = dict(os.environ if env is None else env)
    for inside in ("ORBED_IN_NETNS", "ORBED_NETNS_PIDFILE"):  # scripts/netns-exec would reuse this one
        env.pop(inside, None)
    return Started(verb, [str(a) for a in args], env, output)


def run(verb, *args, env=None, output=None, timeout_s=None):
    """start(...).wait(): the run folder of a finished `scripts/orbed VERB ARGS...`."""
    return start(verb, *args, env=env, output=output).wait(timeout_s)

