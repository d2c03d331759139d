"""sweep: the Table 1 error as SLAM drift, the capture viewpoint, the number of displays and a
collaborator's anchor error vary (scripts/sweep.py on orbed-user-study); sweep.csv and one PNG per
sweep in logs/sweep-<time>-<random>/. sweep.py's output goes to OUT/sweep.log; one progress line
counts the points, and the table of points is printed once at the end."""
import os
import shutil

from . import checks, launch as launch_verb
from .output import Failure, Progress, run_logged, show_failure
from .paths import quiet_build
from .runs import new_run_dir, provenance, write_settings

HELP = "the paper's Table 1 error as drift, capture angle, displays and a collaborator vary"
DESCRIPTION = """The paper's Table 1 error (orbed-user-study, 4 persons x 50 trials per mode and point) as SLAM
drift, the angle between the display's capture and the alignment viewpoints, the number of displays,
and a collaborator's headset as the display (its shared-anchor error) vary; sweep.csv and one PNG
per sweep in logs/sweep-<time>-<random>/. Only the headset's settings (user., slam.,
head_trajectory., hmd.) apply."""
POINTS = {"drift": 6, "capture_angle": 8, "displays": 3, "collaborator": 6}  # scripts/sweep.py's sweeps


def configure(p):
    p.add_argument("--trials", type=checks.whole(1, 9999), metavar="N", help="trials per person and mode (default 50)")
    p.add_argument("--users", type=checks.whole(1, 9999), metavar="N", help="persons per point (default 4)")
    p.add_argument("--only", choices=sorted(POINTS), help="one sweep")
    checks.add_settings(p)


def check(args, parser):
    launch_verb.check_settings_files(args.settings, parser)


def run(args, ctx):
    passed = []
    for flag in ("trials", "users", "only"):
        if getattr(args, flag) is not None:
            passed += [f"--{flag}", str(getattr(args, flag))]
    quiet_build(ctx, ["orbed-user-study", "orbed-hmd", "orbed-assistant"])
    out = new_run_dir(ctx, "sweep-")
    if args.settings:
        # The headset's sections under every point (the swept keys over them); the person's only.
        try:
            lines = write_settings(ctx, os.path.join(out, "settings"), args.settings)
        except Failure:
            shutil.rmtree(out, ignore_errors=True)
            raise Failure("sweep: the settings were refused (above); nothing was started", 2)
        for line in lines:
            name, _, path = line.partition("=")
            if name != "hmd_config":
                shutil.rmtree(out, ignore_errors=True)
                raise Failure("sweep: only the headset's settings (user., slam., head_trajectory., hmd.) apply to a "
                              f"sweep, not {name}", 2)
            passed += ["--base-config", path]
    provenance(ctx, "start", out, "--kind", "sweep", "--config", os.path.join(ctx.root, "hmd_emulator/config/user.yaml"),
               "--config", os.path.join(ctx.root, "hmd_emulator/config/slam.yaml"),
               "--config", os.path.join(ctx.root, "experiments/viraal/viraal.yaml"))
    progress = Progress(ctx.console, "sweep: point", POINTS[args.only] if args.only else sum(POINTS.values()))
    progress.show(f"output in {ctx.rel(out)}/sweep.log")
    rows = []

    def on_line(line):
        if " with display " in line and " AR only " in line:
            rows.append(line.rstrip("\n"))
            progress.step(line.split("  with display")[0].strip())
    log = os.path.join(out, "sweep.log")
    code = run_logged(["/usr/bin/python3", ctx.script("sweep.py"), "--study", os.path.join(ctx.bin, "orbed-user-study"),
                       "--source", ctx.root, "--out", out, *passed], log, ctx.console, on_line=on_line)
    if code:
        show_failure(ctx.console, log)
    else:
        progress.done()
        ctx.console.results("\n".join(rows))
        ctx.say(f"sweep: sweep.csv and the PNGs in {ctx.rel(out)}/")
    provenance(ctx, "finish", out, "--exit-code", str(code))
    return code
