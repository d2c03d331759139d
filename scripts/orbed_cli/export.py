"""export: a run's log as one MCAP file for Foxglove (orbed-log export --mcap) or as CSV tables (--csv)."""
import glob
import os
import subprocess

from . import checks
from .paths import build

HELP = "a run's log as an MCAP file Foxglove opens offline (--csv: one CSV table per channel)"
DESCRIPTION = """Export a recorded log with orbed-log: as one MCAP file (the default) that Foxglove opens offline
with File > Open (the Foxglove bridge's /tf, /scene, camera and display images, registration and
guidance, and every LCM channel as JSON with its JSON Schema; the run's provenance.json as
metadata), or with --csv as one CSV file per channel. LOG is an .lcmlog or a run folder (its log);
OUT defaults to the log's name with .mcap (--csv: a folder named after the log), beside it."""


def configure(p):
    p.add_argument("log", metavar="LOG", help="an .lcmlog, or a run folder under logs/ (its log)")
    p.add_argument("out", metavar="OUT", nargs="?", help="the MCAP file, or --csv: the folder (default: beside LOG)")
    form = p.add_mutually_exclusive_group()
    form.add_argument("--mcap", action="store_true", help="one MCAP file (the default)")
    form.add_argument("--csv", action="store_true", help="one CSV file per channel into the folder OUT")
    p.add_argument("--channels", default=".*", metavar="REGEX", help="only LCM channels whose whole name matches")
    p.add_argument("--from-s", type=checks.non_negative, metavar="A", help="from A seconds after the first event")
    p.add_argument("--to-s", type=checks.non_negative, metavar="B", help="to B seconds after the first event")


def log_of(path):
    """The log a LOG argument names: the file, or a run folder's one .lcmlog (its first part)."""
    if os.path.isdir(path):
        logs = sorted(f for f in glob.glob(os.path.join(path, "*.lcmlog")) if ".part" not in os.path.basename(f))
        return logs[0] if logs else None
    return path if os.path.isfile(path) else None


def check(args, parser):
    if log_of(args.log) is None:
        parser.error(f"no log {args.log}" + (" (a folder with no .lcmlog)" if os.path.isdir(args.log) else ""))
    if args.from_s is not None and args.to_s is not None and float(args.to_s) < float(args.from_s):
        parser.error("--to-s is before --from-s")


def run(args, ctx):
    log = log_of(args.log)
    stem = os.path.splitext(log)[0]
    out = args.out or (stem + "-csv" if args.csv else stem + ".mcap")
    build(ctx, ["orbed-log"] if args.csv else ["orbed-log", "mcap_writer"])
    argv = [os.path.join(ctx.bin, "orbed-log"), "export", log, out, "--csv" if args.csv else "--mcap",
            "--channels", args.channels]
    if args.from_s is not None:
        argv += ["--from-s", args.from_s]
    if args.to_s is not None:
        argv += ["--to-s", args.to_s]
    code = subprocess.run(argv).returncode
    if code == 0 and not args.csv:
        ctx.say(f"export: open {out} in Foxglove (File > Open): a 3D panel on /tf and /scene (display frame W), "
                "Image panels on /hmd/camera, /reflective, /fixed_view, plots of any field")
    return code
