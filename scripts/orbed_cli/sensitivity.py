"""sensitivity: the set-up half's one-at-a-time sensitivity to every assistant parameter without a
source (experiments/setup/sensitivity.yaml), in-process (orbed-setup-study), the same studies per
setting."""
import os
import sys

from . import checks
from .output import Failure, Progress, run_logged, show_failure
from .paths import quiet_build
from .runs import new_run_dir, provenance

HELP = "what each unsourced assistant parameter does to the set-up half's results (one at a time)"
DESCRIPTION = """The set-up half's one-at-a-time sensitivity: for the shipped assistant and for every
(key, value) of experiments/setup/sensitivity.yaml (each parameter whose source is a choice, at the
ends of its band), N simulated studies of the paper's size (8 users x 3 modes x 3 targets) in-process
with orbed-setup-study, the same seeds in every setting. Per setting and mode: mean and median joint
error, half-turn rate, mean execution time; sensitivity.csv and figures/sensitivity.{pdf,png} in
logs/sensitivity-<time>-<random>/."""


def configure(p):
    p.add_argument("--studies", type=checks.whole(1, 10000), default=20, metavar="N",
                   help="studies per setting (default 20)")
    p.add_argument("--seed", type=checks.whole(0, 999999999), default=1, metavar="S", help="the first user's seed")
    p.add_argument("--threads", type=checks.whole(1, 64), default=2, metavar="T",
                   help="users run at a time (default 2)")


def run(args, ctx):
    sys.path.insert(0, os.path.join(ctx.root, "python"))
    from orbed.study import sensitivity  # numpy, pandas: imported only here

    quiet_build(ctx, ["orbed-setup-study"])
    out = new_run_dir(ctx, "sensitivity-")
    log = os.path.join(out, "sensitivity.log")
    provenance(ctx, "start", out, "--kind", "sensitivity", "--setting", f"studies={args.studies}",
               "--setting", f"seed={args.seed}", "--config", sensitivity.SWEEP)
    todo = sensitivity.settings()
    ctx.say(f"sensitivity: {len(todo)} settings x {args.studies} studies in {ctx.rel(out)}/")
    progress = Progress(ctx.console, "sensitivity:", len(todo))
    folders = {}
    for i, (name, key, value) in enumerate(todo):
        progress.show(name)
        folder = os.path.join(out, "%02d" % i)
        os.mkdir(folder)
        argv = [os.path.join(ctx.bin, "orbed-setup-study"), "--studies", str(args.studies), "--users", "8",
                "--targets", "3", "--trials", "3", "--seed", str(args.seed), "--threads", str(args.threads),
                "--allow-failures", "--quiet", "--out", folder]
        if key is not None:
            config = os.path.join(folder, "assistant.yaml")
            with open(config, "w") as f:
                f.write(sensitivity.overlay(key, value))
            argv += ["--assistant-config", config]
        if run_logged(argv, log, ctx.console):
            show_failure(ctx.console, log)
            raise Failure(f"sensitivity: orbed-setup-study failed for {name}")
        folders[name] = folder
        progress.k += 1
    progress.done()
    results = sensitivity.table(folders)
    sensitivity.write(results, out)
    provenance(ctx, "finish", out, "--exit-code", "0")
    base = results[sensitivity.BASELINE]
    for output in ("ar_reflective.mean_error_deg", "ar.mean_error_deg", "fixed.mean_error_deg",
                   "ar_reflective-ar.mean_error_deg", "ar.half_turn_rate"):
        moved = max((n for n in results if n != sensitivity.BASELINE),
                    key=lambda n: abs(results[n].get(output, base[output]) - base[output]))
        ctx.console.echo(f"sensitivity: {output} {base[output]:.3g} at the shipped parameters; moved most by {moved} "
                         f"({results[moved][output]:.3g})")
    ctx.console.echo(f"sensitivity: {ctx.rel(os.path.join(out, 'sensitivity.csv'))}, "
                     f"{ctx.rel(os.path.join(out, 'figures', 'sensitivity.pdf'))}")
    return 0
