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
logs/sensitivity-<time>-<random>/ (`scripts/orbed study --sensitivity N`: into the study's folder and
its report)."""


def configure(p):
    p.add_argument("--studies", type=checks.whole(1, 10000), default=20, metavar="N",
                   help="studies per setting (default 20)")
    p.add_argument("--seed", type=checks.whole(0, 999999999), default=1, metavar="S", help="the first user's seed")
    p.add_argument("--threads", type=checks.whole(1, 64), default=2, metavar="T",
                   help="users run at a time (default 2)")


def settings():
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                                    "python"))
    from orbed.study import sensitivity  # numpy, pandas: imported only here
    return sensitivity


def simulate(ctx, out, studies, seed, threads, progress):
    """Every setting's studies into OUT/<k>/ (OUT exists), then sensitivity.csv and the figure; the
    tool's output in OUT/sensitivity.log. Takes one step of PROGRESS per setting (len(settings)).
    Both `scripts/orbed sensitivity` and `scripts/orbed study --sensitivity N` call it; the binary
    is built. Returns {setting: outputs}."""
    sensitivity = settings()
    log = os.path.join(out, "sensitivity.log")
    folders = {}
    for i, (name, key, value) in enumerate(sensitivity.settings()):
        progress.show(f"sensitivity: {name}")
        folder = os.path.join(out, "%02d" % i)
        os.mkdir(folder)
        argv = [os.path.join(ctx.bin, "orbed-setup-study"), "--studies", str(studies), "--users", "8",
                "--targets", "3", "--trials", "3", "--seed", str(seed), "--threads", str(threads),
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
    results = sensitivity.table(folders)
    sensitivity.write(results, out)
    return results


def say_summary(ctx, out, results):
    sensitivity = settings()
    base = results[sensitivity.BASELINE]
    for output in ("ar_reflective.mean_error_deg", "ar.mean_error_deg", "fixed.mean_error_deg",
                   "ar_reflective-ar.mean_error_deg", "ar.half_turn_rate"):
        moved = max((n for n in results if n != sensitivity.BASELINE),
                    key=lambda n: abs(results[n].get(output, base[output]) - base[output]))
        ctx.console.echo(f"sensitivity: {output} {base[output]:.3g} at the shipped parameters; moved most by {moved} "
                         f"({results[moved][output]:.3g})")
    ctx.console.echo(f"sensitivity: {ctx.rel(os.path.join(out, 'sensitivity.csv'))}, "
                     f"{ctx.rel(os.path.join(out, 'figures', 'sensitivity.pdf'))}")


def count():
    return len(settings().settings())


def run(args, ctx):
    quiet_build(ctx, ["orbed-setup-study"])
    out = new_run_dir(ctx, "sensitivity-")
    sensitivity = settings()
    provenance(ctx, "start", out, "--kind", "sensitivity", "--setting", f"studies={args.studies}",
               "--setting", f"seed={args.seed}", "--config", sensitivity.SWEEP)
    ctx.say(f"sensitivity: {count()} settings x {args.studies} studies in {ctx.rel(out)}/")
    progress = Progress(ctx.console, "sensitivity:", count())
    results = simulate(ctx, out, args.studies, args.seed, args.threads, progress)
    progress.done()
    provenance(ctx, "finish", out, "--exit-code", "0")
    say_summary(ctx, out, results)
    return 0
