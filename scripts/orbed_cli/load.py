"""load: the testbed at F x its nominal rates for N s, measured by orbed-load (tests/load) in a
private namespace; logs in logs/load-<time>-<random>/. orbed-load's chatter (stderr) goes to
RUN/load.log (and the testbed's), its report is printed once at the end; one progress line
counts the seconds."""
import os
import re
import threading

from . import checks
from .output import Progress, run_logged, show_failure
from .paths import quiet_build
from .runs import new_run_dir, provenance

HELP = "run the testbed at F times its nominal rates for N s and measure it (orbed-load)"
DESCRIPTION = """Run the testbed (scripts/launch/load.yaml) at F times its nominal rates (default 10) for N s
(default 60) in a private network namespace with orbed-load; prints resident memory at 10 s and at
the end, respawns and drops per process, wanted and achieved rate per stream; fails if a process
died or was respawned or grew more than 10 % in memory."""


def configure(p):
    p.add_argument("--duration-s", type=checks.positive, default="60", metavar="N", help="seconds (default 60)")
    p.add_argument("--factor", type=checks.positive, default="10", metavar="F", help="times the nominal rates (default 10)")


def report(log):
    """orbed-load's report from its log: from the process table's header on, without the lines
    the testbed's processes and orbed-launch print while they stop."""
    with open(log, errors="replace") as f:
        lines = f.read().splitlines()
    first = max([i for i, line in enumerate(lines) if re.match(r"process\s+CPU %", line)], default=len(lines))
    return "\n".join(line for line in lines[first:]
                     if not line.startswith("[orbed-launch]") and not re.match(r"^[\w-]+\s*\| ", line))


def run(args, ctx):
    quiet_build(ctx, ["testbed", "orbed-load"])
    run_dir = new_run_dir(ctx, "load-")
    os.makedirs(ctx.netns_dir, exist_ok=True)
    pidfile = os.path.join(ctx.netns_dir, os.path.basename(run_dir) + ".pid")
    provenance(ctx, "start", run_dir, "--kind", "load", "--launch", os.path.join(ctx.root, "scripts/launch/load.yaml"),
               "--setting", f"duration_s={args.duration_s}", "--setting", f"factor={args.factor}")
    ctx.say(f"load: {args.factor} x nominal rates for {args.duration_s} s, logs in {ctx.rel(run_dir)}")
    env = dict(os.environ, ORBED_SOURCE_DIR=ctx.root, ORBED_NETNS_PIDFILE=pidfile)
    log = os.path.join(run_dir, "load.log")
    progress = Progress(ctx.console, "load: second", max(1, round(float(args.duration_s))))
    stop = threading.Event()

    def tick():  # the progress line once a second while orbed-load runs (display only)
        while not stop.wait(1.0):
            progress.k = min(progress.n - 1, round(progress.elapsed()))
            progress.show()
    ticker = threading.Thread(target=tick, daemon=True)
    ticker.start()
    try:
        code = run_logged([ctx.script("netns-exec"), os.path.join(ctx.bin, "orbed-load"), "--duration-s",
                           str(args.duration_s), "--factor", str(args.factor), "--log-dir", run_dir], log, ctx.console,
                          env=env)
    finally:
        stop.set()
        ticker.join()
        if os.path.exists(pidfile):
            os.remove(pidfile)
    progress.done()
    ctx.console.results(report(log))
    if code:
        show_failure(ctx.console, log)
    provenance(ctx, "finish", run_dir, "--exit-code", str(code))
    ctx.say(f"load: exit code {code}; log folder {ctx.rel(run_dir)}")
    return code
