"""scale: scripts/scale.py runs orbed-load over a grid of arms x headsets, each point in its own
private namespace, and writes the table, the fit and the plot into logs/scale-<time>-<random>/.
Its output goes to OUT/scale.log; one progress line counts the points; the table is printed once."""
import os
import re

from . import checks
from .output import Progress, run_logged, show_failure
from .paths import quiet_build
from .runs import new_run_dir, provenance

HELP = "the testbed as arms x headsets grow: CPU, memory, rates, drops and latency per point"
DESCRIPTION = """The testbed as arms x headsets grow (default 1x1 ... 4x4 and 4x8, 30 s each, nominal rates):
orbed-load --arms A --headsets H per point in its own namespace; CPU, memory, rates, drops and
camera latency per point, the cost of each added arm and headset; scale.csv, scale.json and
scale.png in logs/scale-<time>-<random>/ (scripts/scale.py)."""
DEFAULT_GRID = "1x1,2x1,4x1,1x2,1x4,2x2,3x3,4x4,4x8"  # scripts/scale.py's


def configure(p):
    p.add_argument("--grid", type=checks.grid, metavar="AxH,...", help=f"the points (default {DEFAULT_GRID})")
    p.add_argument("--duration-s", type=checks.positive, metavar="N", help="each point's run after ready (default 30)")
    p.add_argument("--factor", type=checks.positive, metavar="F", help="times the nominal rates (default 1)")
    p.add_argument("--keep-logs", action="store_true", help="keep each point's .lcm log")


def run(args, ctx):
    passed = []
    for flag in ("grid", "duration_s", "factor"):
        if getattr(args, flag) is not None:
            passed += [f"--{flag.replace('_', '-')}", str(getattr(args, flag))]
    if args.keep_logs:
        passed.append("--keep-logs")
    quiet_build(ctx, ["testbed", "orbed-load"])
    out = new_run_dir(ctx, "scale-")
    provenance(ctx, "start", out, "--kind", "scale", "--launch", os.path.join(ctx.root, "scripts/launch/load.yaml"))
    progress = Progress(ctx.console, "scale: point", len((args.grid or DEFAULT_GRID).split(",")))
    progress.show(f"output in {ctx.rel(out)}/scale.log")
    table = []

    def on_line(line):
        m = re.match(r"scale: \[(\d+)/(\d+)\] (.*?),", line)
        if m:
            progress.k = int(m.group(1)) - 1
            progress.show(m.group(3))
        elif re.match(r"scale:\s+CPU", line):
            progress.step()
        elif line.startswith("|") or (table and not line.startswith("scale: [")):
            table.append(line.rstrip("\n"))
    log = os.path.join(out, "scale.log")
    env = dict(os.environ, ORBED_SOURCE_DIR=ctx.root)
    code = run_logged(["/usr/bin/python3", ctx.script("scale.py"), "--load", os.path.join(ctx.bin, "orbed-load"),
                       "--netns-exec", ctx.script("netns-exec"), "--out", out, *passed], log, ctx.console, env=env,
                      on_line=on_line)
    if code:
        show_failure(ctx.console, log)
    else:
        progress.done()
        ctx.console.results("\n".join(table))
    provenance(ctx, "finish", out, "--exit-code", str(code))
    return code
