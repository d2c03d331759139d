"""launch: a launch file in a private network namespace, in a new run folder with its provenance
record. Also the launch step of run and study (launch())."""
import json
import os
import shutil
import subprocess

from . import checks
from .netns import LAN_URL, netns_exec
from .output import Failure, run_logged
from .paths import need_binaries
from .runs import launch_settings, new_run_dir, provenance, write_settings

HELP = "run a launch file in a private network namespace, in a new run folder"
DESCRIPTION = """Run a launch file (default scripts/launch/testbed.yaml) in a private network namespace
(loopback only), in a new run folder logs/<UTC time>-<random>/ with its provenance.json. --arg sets
one of the file's arguments (build/bin/orbed-launch FILE --show-args lists them); --lan uses the host
network with ttl=1 to reach other machines; --host names this machine for the file's `host:`
(default hostname). SETTINGS (--config, --set) are written into the run folder (settings/) and
passed to the launch arguments that read them."""


def add_launch_flags(p):
    p.add_argument("--duration-s", type=checks.positive, metavar="N", help="stop after N seconds")
    p.add_argument("--lan", action="store_true", help="the host network, ttl=1 (other machines)")
    p.add_argument("--host", metavar="NAME", help="this machine's name for the file's host: (default hostname)")
    p.add_argument("--arg", action="append", default=[], type=checks.key_value, metavar="NAME=VALUE",
                   help="one of the launch file's arguments (repeatable)")
    checks.add_settings(p)


def configure(p):
    p.add_argument("file", nargs="?", metavar="FILE", help="the launch file (default scripts/launch/testbed.yaml)")
    add_launch_flags(p)


def check_settings_files(settings, parser):
    for flag, value in settings:
        if flag == "--config" and not os.path.isfile(value):
            parser.error(f"--config: no file {value}")


def check(args, parser):
    if args.file and not os.path.isfile(args.file):
        parser.error(f"no launch file {args.file}")
    check_settings_files(args.settings, parser)


def run(args, ctx):
    code, _ = launch(ctx, args.file or ctx.default_launch, duration=args.duration_s, lan=args.lan,
                     host=args.host, args=args.arg, settings=args.settings)
    return code


def launch(ctx, file, duration=None, lan=False, host=None, args=(), settings=(), into=None, name=None, log=None):
    """Runs orbed-launch FILE in a new run folder (INTO/NAME for a study's user, which must not
    exist yet); returns (exit code, run folder). The launch's arguments and the settings are
    checked before anything starts; a refused one removes the new folder (Failure, code 2). With
    LOG, everything it and its processes print goes to that file."""
    need_binaries(ctx)
    out = open(log, "a") if log else None
    note = (lambda m: (out.write(f"orbed: {m}\n"), out.flush())) if out else ctx.say
    try:
        if into:
            run_dir = os.path.join(into, name)
            try:
                os.mkdir(run_dir)
            except FileExistsError:
                raise Failure(f"launch: {run_dir} exists already (a run folder belongs to one run)")
        else:
            run_dir = new_run_dir(ctx, "")
        os.makedirs(ctx.netns_dir, exist_ok=True)
        launch_args = list(args)
        env = dict(os.environ, ORBED_LOG_DIR=run_dir, ORBED_SOURCE_DIR=ctx.root,
                   ORBED_LAUNCH_FILE=os.path.realpath(file))
        orbed_launch = os.path.join(ctx.bin, "orbed-launch")

        def refuse(message):
            shutil.rmtree(run_dir, ignore_errors=True)
            raise Failure(f"launch: {message}; nothing was started", 2)

        if settings:
            # Each overlay goes to the launch argument that passes it on; a launch without that
            # argument has no process that reads those settings: refused, or, for a study's user,
            # left out (the assistant's settings reach its set-up runs, not its ViRAAl runs).
            try:
                lines = write_settings(ctx, os.path.join(run_dir, "settings"), settings)
            except Failure:
                refuse("the settings were refused (above)")
            shown = subprocess.run([orbed_launch, file, "--show-args", "--json"], stdout=subprocess.PIPE, text=True,
                                   stderr=out, env=env)
            if shown.returncode != 0:
                refuse(f"orbed-launch cannot read {file} (above)")
            declared = json.loads(shown.stdout)
            for line in lines:
                if line.partition("=")[0] in declared:
                    launch_args.append(line)
                elif not into:
                    refuse(f"{os.path.basename(file)} runs no process that reads these settings "
                           f"(it has no argument {line.partition('=')[0]})")
        # The launch's arguments as they will be, checked (a name it does not declare is refused).
        arg_flags = [x for a in launch_args for x in ("--arg", a)]
        with open(os.path.join(run_dir, "launch_arguments.json"), "w") as f:
            shown = subprocess.run([orbed_launch, file, "--show-args", "--json", *arg_flags], stdout=f, stderr=out, env=env)
        if shown.returncode != 0:
            refuse("orbed-launch refused the launch (above)")
        provenance(ctx, "start", run_dir, "--kind", "launch", "--launch", file, *launch_settings(env),
                   *(["--parent", into] if into else []))
        argv = [orbed_launch, file, *arg_flags]
        if duration:
            argv += ["--duration-s", str(duration)]
        if host:
            argv += ["--host", host]
        note(f"launch: {os.path.basename(file)}, logs in {ctx.rel(run_dir)}")
        if lan:
            note("launch: --lan: host network, ttl=1 (reaches this LAN segment)")
            env["ORBED_LCM_URL"] = LAN_URL
            if out:
                out.close()
                out = None
                code = run_logged(argv, log, ctx.console, env=env)
            else:
                code = subprocess.run(argv, env=env).returncode
        else:
            prefix = f"{os.path.basename(into)}-" if into else ""
            pidfile = os.path.join(ctx.netns_dir, f"launch-{prefix}{os.path.basename(run_dir)}.pid")
            if out:
                env["ORBED_NETNS_PIDFILE"] = pidfile
                out.close()
                out = None
                code = run_logged([ctx.script("netns-exec"), *argv], log, ctx.console, env=env)
                if os.path.exists(pidfile):
                    os.remove(pidfile)
            else:
                code = netns_exec(ctx, argv, pidfile=pidfile, env=env)
        if log:
            out = open(log, "a")
            note = lambda m: (out.write(f"orbed: {m}\n"), out.flush())  # noqa: E731
        provenance(ctx, "finish", run_dir, "--exit-code", str(code))
        note(f"launch: exit code {code}; log folder {ctx.rel(run_dir)}")
        return code, run_dir
    finally:
        if out:
            out.close()
