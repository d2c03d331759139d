"""run: the paper's ViRAAl experiment (scripts/launch/viraal.yaml) and its results table.
orbed-scenario ends the launch when it is done; the --duration-s is only a safety net."""
import glob
import json
import os
import subprocess

from . import launch as launch_verb
from .paths import build

HELP = "set up, build and run the paper's ViRAAl experiment; print its results table"
DESCRIPTION = """Set up, build the executables, run the paper's ViRAAl experiment (scripts/launch/viraal.yaml)
and print its results table and where the log is. The same run id gives the same numbers (default: a
new id from the clock); --resume continues the run whose folder (logs/<run>) holds a partial
results.json. Takes launch's flags too (--arg, --duration-s, --lan, --host) and SETTINGS (--config,
--set)."""


def configure(p):
    p.add_argument("--run-id", metavar="ID", help="the run id (seeds the alignments)")
    p.add_argument("--resume", metavar="DIR", help="continue the run in folder DIR (logs/<run>)")
    launch_verb.add_launch_flags(p)
    p.set_defaults(duration_s="300")


def check(args, parser):
    if args.resume and not os.path.isdir(args.resume):
        parser.error(f"--resume: no run folder {args.resume}")
    launch_verb.check_settings_files(args.settings, parser)


def log_summary(ctx, run_dir):
    """The log's manifest: events, bytes, drops and each channel's rate."""
    logs = sorted(glob.glob(os.path.join(run_dir, "*.lcmlog")))
    if not logs:
        ctx.say(f"no log in {run_dir}")
        return
    with open(os.path.join(run_dir, "manifest.json")) as f:
        m = json.load(f)
    lines = [f"\nlog: {m['log_file']}  ({m['events_written']} events, {m['bytes_written']} bytes, "
             f"{m['drops']} dropped, complete={m['complete']})"]
    if len(m["parts"]) > 1:
        for p in m["parts"]:
            lines.append(f"  part {p['file']}: {p['events']} events" + ("" if p["complete"] else
                         f", its logger died (valid up to its last flush; {p['damaged_bytes']} damaged bytes)"))
    lines.append(f"{'channel':<22} {'events':>8} {'bytes':>12} {'rate_hz':>8}")
    for name, c in sorted(m["channels"].items()):
        span = max(1e-9, (c["last_utime"] - c["first_utime"]) / 1e6)
        rate = (c["events"] - 1) / span if c["events"] > 1 else 0.0
        lines.append(f"{name:<22} {c['events']:>8} {c['bytes']:>12} {rate:>8.1f}")
    ctx.console.results("\n".join(lines))
    ctx.say(f"replay it:  scripts/orbed replay {logs[0]}   (inspect: scripts/orbed spy --log {logs[0]})")


def results(ctx, run_dir):
    """The ViRAAl results table (orbed-scenario --print); 1 when results.json is missing."""
    path = os.path.join(run_dir, "results.json")
    if not os.path.isfile(path):
        ctx.console.results(f"\nno {path}: the scenario did not get to write its results (see the output above)")
        return 1
    ctx.console.results("")
    code = subprocess.run([os.path.join(ctx.bin, "orbed-scenario"), "--print", path]).returncode
    if code == 3:
        ctx.console.results(f"continue it with: scripts/orbed run --resume {run_dir}")
    return code


def run(args, ctx):
    launch_args = list(args.arg)
    if args.run_id:
        launch_args.append(f"run_id={args.run_id}")
    if args.resume:
        launch_args.append(f"resume={os.path.realpath(args.resume)}")
    build(ctx, ["testbed"])
    code, run_dir = launch_verb.launch(ctx, ctx.run_launch, duration=args.duration_s, lan=args.lan, host=args.host,
                                       args=launch_args, settings=args.settings)
    log_summary(ctx, run_dir)
    result = results(ctx, run_dir)
    logs = sorted(glob.glob(os.path.join(run_dir, "*.lcmlog")))
    ctx.say(f"log:      {ctx.rel(run_dir)}/{os.path.basename(logs[0]) if logs else ''}")
    ctx.say(f"manifest: {ctx.rel(run_dir)}/manifest.json")
    ctx.say(f"results:  {ctx.rel(run_dir)}/results.json")
    return code or result
