"""fit: the AR-only calibration of the ViRAAl user made again (scripts/fit.py on orbed-user-study)."""
import os
import subprocess

from . import checks
from .paths import build
from .runs import new_run_dir, provenance

HELP = "the one calibration made again: the AR-only row of Table 1 over a grid; fit.csv"
DESCRIPTION = """The one calibration made again: the AR-only row of Table 1 (30.2 +/- 23.9 mm) over a grid of
the user's depth-bias std and person-to-person spread, 48 persons x 50 trials per point; fit.csv in
logs/fit-<time>-<random>/."""


def configure(p):
    p.add_argument("--users", type=checks.whole(1, 9999), metavar="N", help="persons per point (default 48)")
    p.add_argument("--trials", type=checks.whole(1, 9999), metavar="N", help="trials per person (default 50)")
    p.add_argument("--depth-bias", type=checks.numbers, metavar="A,B,..", help="depth-bias stds to try")
    p.add_argument("--log-sigma", type=checks.numbers, metavar="A,B,..", help="person-to-person spreads to try")


def run(args, ctx):
    passed = []
    for flag in ("users", "trials", "depth_bias", "log_sigma"):
        if getattr(args, flag) is not None:
            passed += [f"--{flag.replace('_', '-')}", str(getattr(args, flag))]
    build(ctx, ["orbed-user-study"])
    out = new_run_dir(ctx, "fit-")
    provenance(ctx, "start", out, "--kind", "fit", "--config", os.path.join(ctx.root, "hmd_emulator/config/user.yaml"),
               "--config", os.path.join(ctx.root, "hmd_emulator/config/slam.yaml"),
               "--config", os.path.join(ctx.root, "experiments/viraal/viraal.yaml"))
    code = subprocess.run(["/usr/bin/python3", ctx.script("fit.py"), "--study", os.path.join(ctx.bin, "orbed-user-study"),
                           "--source", ctx.root, "--out", out, *passed]).returncode
    provenance(ctx, "finish", out, "--exit-code", str(code))
    return code
