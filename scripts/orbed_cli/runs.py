"""Run folders, their provenance records (scripts/provenance.py) and a run's settings
(scripts/settings.py; each overlay checked by the process that reads it)."""
import os
import random
import string
import subprocess
import time

from .output import Failure

# Environment variables that say where things are, not how a launch's processes behave.
NOT_SETTINGS = {"ORBED_LOG_DIR", "ORBED_LOGS_DIR", "ORBED_SOURCE_DIR", "ORBED_LAUNCH_FILE", "ORBED_BUILD_DIR",
                "ORBED_ASAN_BUILD_DIR", "ORBED_BIN_DIR", "ORBED_JOBS", "ORBED_NETNS_PIDFILE", "ORBED_IN_NETNS",
                "ORBED_LCM_URL"}


def utc_stamp():
    return time.strftime("%Y%m%dT%H%M%SZ", time.gmtime())


def new_run_dir(ctx, prefix, parent=None):
    """A new folder PARENT/PREFIX<UTC time>-<6 random characters> (PARENT default the logs folder).
    mkdir fails when the name exists, and then another is tried: two commands started in the same
    second never share a folder."""
    parent = parent or ctx.logs
    os.makedirs(parent, exist_ok=True)
    letters = string.ascii_letters + string.digits
    for _ in range(100):
        path = os.path.join(parent, f"{prefix}{utc_stamp()}-{''.join(random.choices(letters, k=6))}")
        try:
            os.mkdir(path, 0o755)
        except FileExistsError:
            continue
        os.chmod(path, 0o755)
        return path
    raise Failure(f"cannot make a run folder in {parent}")


def provenance(ctx, *args):
    """provenance.py start|finish RUN ...; start gets `-- COMMAND LINE` appended."""
    argv = ["/usr/bin/python3", ctx.script("provenance.py"), *args]
    if args[0] == "start":
        argv += ["--", *ctx.command_line]
    if subprocess.run(argv).returncode != 0:
        raise Failure(f"cannot write the provenance record of {ctx.rel(args[1])}")


def launch_settings(environ=None):
    """The settings a launch's processes take from the environment (every ORBED_* variable but
    those that say where things are), as --setting KEY=VALUE arguments for the record."""
    environ = os.environ if environ is None else environ
    out = []
    for name in sorted(k for k in environ if k.startswith("ORBED_") and k not in NOT_SETTINGS):
        out += ["--setting", f"{name}={environ[name]}"]
    return out


def settings_argv(settings):
    """[('--config', FILE), ('--set', KV)] -> settings.py's arguments (files made absolute)."""
    argv = []
    for flag, value in settings:
        argv += [flag, os.path.realpath(value) if flag == "--config" else value]
    return argv


def write_settings(ctx, folder, settings):
    """The run's settings as overlay files in FOLDER (scripts/settings.py), each checked by the
    process that reads it (--check-config). Returns the launch arguments that pass them on
    (["hmd_config=...", "assistant_config=..."]); Failure when refused (settings.py and the
    readers say why on stderr)."""
    done = subprocess.run(["/usr/bin/python3", ctx.script("settings.py"), folder, *settings_argv(settings)],
                          stdout=subprocess.PIPE, text=True)
    if done.returncode != 0:
        raise Failure("the settings were refused (above)", 2)
    lines = [line for line in done.stdout.splitlines() if line]
    readers = {"hmd_config": "orbed-hmd", "assistant_config": "orbed-assistant"}
    for line in lines:
        name, _, path = line.partition("=")
        if name in readers:
            checked = subprocess.run([os.path.join(ctx.bin, readers[name]), "--check-config", "--config", path],
                                     stdout=subprocess.DEVNULL)
            if checked.returncode != 0:
                raise Failure("the settings were refused (above)", 2)
    return lines
