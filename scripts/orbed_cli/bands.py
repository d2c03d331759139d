"""bands: the model's predictive bands for every figure of the paper's Tables 1-4, from many simulated
studies of the paper's size run in-process (orbed-user-study --studies, orbed-setup-study --studies),
and how often the paper's Table 1 measurement ranks the two display modes opposite to the truth."""
import os
import re
import sys

from . import checks
from .output import Failure, Progress, run_logged, show_failure
from .paths import quiet_build
from .runs import new_run_dir, provenance

HELP = "predictive bands: M simulated studies of the paper's size, the paper's figures inside or not"
DESCRIPTION = """The model's predictive bands: M simulated studies of the paper's size (ViRAAl 4 users x 10
trials per mode; set-up 8 users x 3 modes x 3 targets, N = 3 alignments before each headset
set-up), run in-process by the same cores as the bus (orbed-user-study --studies, orbed-setup-study
--studies; study m is `scripts/orbed study --seed S+U*m`). For every figure of Tables 1-4, the 95 %
predictive interval over the studies and whether the paper's figure is inside; the figures a
parameter was fitted to (experiments/calibration.yaml) are shown and not counted; prints k of n.
Also the rank flip: how often the paper's Table 1 measurement orders the two display modes
opposite to the truth. Writes bands.csv, bands.json, figures/bands.{pdf,png}, rank_flip.csv and
the studies' CSVs into logs/bands-<time>-<random>/."""

STEP = re.compile(r"(\d+)/(\d+) (?:studies|users)")


def configure(p):
    p.add_argument("--studies", type=checks.whole(1, 100000), default=1000, metavar="M",
                   help="simulated studies (default 1000)")
    p.add_argument("--seed", type=checks.whole(0, 999999999), default=1, metavar="S", help="the first user's seed")
    p.add_argument("--threads", type=checks.whole(1, 64), default=2, metavar="T",
                   help="set-up users run at a time (default 2)")


BINARIES = ["orbed-user-study", "orbed-setup-study", "orbed-study-tables"]
STEPS = 4  # the progress steps simulate() takes: ViRAAl, set-up, the paper's figures, the bands


def step(ctx, progress, what, argv, log):
    """One in-process tool, its progress lines (k/n) shown on the bands' progress line."""
    progress.show(what)

    def on_line(line):
        found = STEP.search(line)
        if found:
            progress.show(f"{what}, {found.group(1)}/{found.group(2)}")

    if run_logged(argv, log, ctx.console, on_line=on_line):
        show_failure(ctx.console, log)
        raise Failure(f"bands: {os.path.basename(argv[0])} failed")
    progress.k += 1


def simulate(ctx, out, studies, seed, threads, progress):
    """The bands' work into the folder OUT (it exists): M studies of each half in-process, the paper's
    figures, then bands.{csv,json}, figures/bands.{pdf,png}; the tools' output in OUT/bands.log. Takes
    STEPS steps of PROGRESS. Returns (bands.write's summary, rank_flip.summarize's). Both `scripts/orbed
    bands` and `scripts/orbed study --bands M` (into STUDY/bands/) call it; the binaries are built."""
    log = os.path.join(out, "bands.log")
    step(ctx, progress, "ViRAAl studies", [os.path.join(ctx.bin, "orbed-user-study"), "--studies", str(studies),
                                           "--users", "4", "--trials", "10", "--user-seed", str(seed),
                                           "--csv", os.path.join(out, "rank_flip.csv"), "--tables-dir", out], log)
    step(ctx, progress, "set-up studies", [os.path.join(ctx.bin, "orbed-setup-study"), "--studies", str(studies),
                                           "--users", "8", "--targets", "3", "--trials", "3", "--seed", str(seed),
                                           "--threads", str(threads), "--allow-failures", "--out", out], log)
    step(ctx, progress, "the paper's figures",
         [os.path.join(ctx.bin, "orbed-study-tables"), "--paper-only", "--out", out], log)
    progress.show("the bands")
    sys.path.insert(0, os.path.join(ctx.root, "python"))
    from orbed.study import bands, rank_flip  # numpy, scipy and statsmodels: imported only here

    try:
        summary = bands.write(out)
        flips = rank_flip.summarize(rank_flip.read_rows(os.path.join(out, "rank_flip.csv")))
    except (OSError, ValueError, KeyError) as e:
        raise Failure(f"bands: the bands of {ctx.rel(out)} failed ({e})")
    progress.k += 1
    return summary, flips


def say_summary(ctx, out, summary, flips):
    """The bands' lines on the console: k of n, the figures outside, the rank flip, the files."""
    outside = [r["figure"] for r in summary["figures"]
               if not r["inside"] and not r["calibrated"] and not r.get("alternative")]
    ctx.console.echo(f"bands: {summary['inside']} of {summary['counted']} paper figures inside their 95 % predictive "
                     f"interval over {summary['studies']} studies ({len(summary['calibrated'])} calibrated, not "
                     f"counted); outside: {', '.join(outside) if outside else 'none'}")
    ctx.console.echo(f"bands: the paper's Table 1 measurement ranks ar_reflective and ar opposite to the truth "
                     f"(translation error) in {flips['flips']} of {flips['studies']} studies, "
                     f"{100 * flips['fraction']:.1f} % (95 % Wilson interval {100 * flips['low']:.1f}-"
                     f"{100 * flips['high']:.1f} %)")
    for relation, modes in (summary.get("by_relation") or {}).items():
        ctx.console.echo(f"bands: set-ups whose start is '{relation}' to the target: " + "; ".join(
            f"{mode} median {v['median_deg']:.1f} deg, mean {v['mean_deg']:.1f} deg, half turns "
            f"{100 * v['half_turn_rate']:.1f} % ({v['setups']} set-ups)" for mode, v in modes.items()))
    ctx.console.echo(f"bands: {ctx.rel(os.path.join(out, 'bands.csv'))}, {ctx.rel(os.path.join(out, 'figures', 'bands.pdf'))}")


def run(args, ctx):
    quiet_build(ctx, BINARIES)
    out = new_run_dir(ctx, "bands-")
    provenance(ctx, "start", out, "--kind", "bands", "--setting", f"studies={args.studies}",
               "--setting", f"seed={args.seed}", "--config", os.path.join(ctx.root, "experiments/calibration.yaml"))
    ctx.say(f"bands: {args.studies} studies in {ctx.rel(out)}/ (the tools' output in bands.log)")
    progress = Progress(ctx.console, "bands:", STEPS)
    summary, flips = simulate(ctx, out, args.studies, args.seed, args.threads, progress)
    progress.done()
    provenance(ctx, "finish", out, "--exit-code", "0")
    say_summary(ctx, out, summary, flips)
    return 0
