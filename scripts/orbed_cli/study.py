"""study: the paper's ViRAAl design (Sec. III-B: 4 users x 10 trials per display mode) and its robot
set-up design (Sec. IV-B: 8 users x 3 guidance modes x 3 targets) over the bus: one launch per user,
each a different emulated person (--arg user_seed=S, S+1, ...). Then orbed-study-tables writes the
study's files, the analysis (python/orbed/study: scipy, statsmodels) its tables and scripts/report.py
the report into logs/study-<time>-<random>/. Each user's launch
prints into STUDY/<name>.log (shown with --verbose); one progress line says how far the study is."""
import collections
import csv
import glob
import json
import os
import shutil
import subprocess
import sys
import tempfile

from . import bands as bands_verb, checks, launch as launch_verb, sensitivity as sensitivity_verb
from .output import Failure, Progress, run_logged, show_failure
from .paths import quiet_build
from .runs import new_run_dir, provenance, write_settings

HELP = "the paper's two studies over the bus (ViRAAl and robot set-up), tables and report"
DESCRIPTION = """The paper's two studies over the bus, each user a different emulated person (--user-seed S,
S+1, ...). ViRAAl: one run of viraal.yaml per user (default 4 users, 10 trials per display mode).
Robot set-up: one run of setup.yaml per user (default 8 users, the three guidance modes in an order
drawn from the seed; the patient and K (start, target) pairs drawn from the seed out of the design
catalog experiments/setup/design.json, the same for every mode, default K = 3; 3 alignments before
each headset set-up). Then
alignment_trials.csv, alignment_means.csv, landmark_validation.csv, setup_joints.csv,
setup_times.csv, setup_docking.csv, tables.json, report.html and figures/ in
logs/study-<time>-<random>/ (every user's run folder inside it, and each one's output in
<name>.log), and Tables 1, 2 and 4 beside the paper's, Table 3 as the paper read it (pooled) and with
the set-up as the unit (paired), the docking error, collisions and a power analysis. --users 0 or --setup-users 0 leaves a half out; --registration-share runs each set-up
user's headset modes again with the true registration (the registration's share of the error).
--bands M then runs M simulated studies of the paper's size in-process with the same seed (what
`scripts/orbed bands --studies M --seed S` does) into STUDY/bands/, and the report shows them.
The run ids (which seed the alignments) are ID-u<k> and ID-setup-u<k>, ID by default study-s<S>: the
same arguments give the same study, bit for bit: every process runs on the sim's clock in lockstep
(steps_per_tick=10), so neither the machine's load nor the rate changes a number; --sim-rate R
(1-100, default 100) is the most times faster than real time the sim may run (1 lets a person
watch at real time); --realtime puts the processes back on the wall clock, without lockstep (R must
be 1). Ends with its wall time, whether every launch's log is complete, and what the logger and the
processes dropped."""


def configure(p):
    p.add_argument("--users", type=checks.whole(0, 99), default=4, metavar="N", help="ViRAAl users (default 4)")
    p.add_argument("--trials", type=checks.whole(1, 999), default=10, metavar="N",
                   help="ViRAAl trials per display mode (default 10)")
    p.add_argument("--setup-users", type=checks.whole(0, 99), default=8, metavar="N", help="set-up users (default 8)")
    p.add_argument("--targets", type=checks.whole(1, 6), default=3, metavar="K",
                   help="set-up (start, target) pairs per mode drawn from experiments/setup/design.json, 1..6 "
                        "(the smallest patient's count of targets bounds it; default 3)")
    p.add_argument("--seed", type=checks.whole(0, 999999999), default=1, metavar="S", help="the first user's seed")
    p.add_argument("--run-id", type=checks.run_id, metavar="ID", help="default study-s<S>")
    p.add_argument("--registration-share", action="store_true",
                   help="the set-up users' headset modes again with the true registration")
    p.add_argument("--sensitivity", type=checks.whole(0, 10000), default=0, metavar="N",
                   help="after the study, the set-up half's one-at-a-time sensitivity with N studies per setting "
                        "into STUDY/sensitivity/ (scripts/orbed sensitivity; default 0: none)")
    p.add_argument("--bands", type=checks.whole(0, 100000), default=0, metavar="M",
                   help="after the study, its predictive bands from M simulated studies into STUDY/bands/ "
                        "(default 0: none)")
    p.add_argument("--sim-rate", type=checks.whole(1, 100), default=100, metavar="R",
                   help="the most times faster than real time the sim may run (default 100)")
    p.add_argument("--realtime", action="store_true", help="the wall clock, without lockstep (needs --sim-rate 1)")
    checks.add_settings(p)


def check(args, parser):
    if args.users == 0 and args.setup_users == 0:
        parser.error("--users 0 and --setup-users 0 leave nothing to run")
    if args.realtime and args.sim_rate != 1:
        parser.error("--realtime keeps the wall clock, so --sim-rate must be 1")
    launch_verb.check_settings_files(args.settings, parser)


def drops(ctx, study_dir):
    """The study's own benchmark line: launches, complete logs, and the work the logger and the
    processes dropped (each one's last PROCESS_STATUS in the log)."""
    n = complete = logger_drops = 0
    dropped = collections.Counter()  # reason -> count over the study
    with open(os.path.join(study_dir, "runs.txt")) as f:
        runs = [line.split() for line in f if line.strip()]
    for fields in runs:
        n += 1
        folder = os.path.join(study_dir, fields[-2])
        with open(os.path.join(folder, "manifest.json")) as f:
            m = json.load(f)
        complete += bool(m.get("complete"))
        logger_drops += int(m.get("drops", 0))
        last = {}  # process -> its last heartbeat's drops by reason
        with tempfile.TemporaryDirectory() as tmp:
            for log in sorted(glob.glob(os.path.join(folder, "*.lcmlog"))):
                subprocess.run([os.path.join(ctx.bin, "orbed-log"), "export", "--channels", "PROCESS_STATUS", log, tmp],
                               check=True, stdout=subprocess.DEVNULL)
                with open(os.path.join(tmp, "PROCESS_STATUS.csv")) as f:
                    for row in csv.DictReader(f):
                        k = int(row["num_drop_reasons"])
                        last[row["name"]] = {row[f"drop_reason[{i}]"]: int(row[f"drop_count[{i}]"]) for i in range(k)}
        for reasons in last.values():
            dropped.update(reasons)
    worst = ", ".join(f"{r} {c}" for r, c in dropped.most_common(3))
    return (f"{n} launches, {complete} logs complete, {logger_drops} events dropped by the logger, "
            f"{sum(dropped.values())} dropped by the processes" + (f" ({worst})" if worst else ""))


def analyze(ctx, study_dir, log):
    """The study's analysis (python/orbed/study) on the CSVs orbed-study-tables wrote: the tables into
    tables.json, their summary appended to the log."""
    sys.path.insert(0, os.path.join(ctx.root, "python"))
    from orbed.study import analysis  # scipy and statsmodels: imported only when a study ends

    try:
        tables = analysis.write(study_dir)
    except (OSError, ValueError, KeyError) as e:
        raise Failure(f"study: the analysis of {ctx.rel(study_dir)} failed ({e})")
    with open(log, "a") as f:
        f.write(analysis.summary(tables))


def run(args, ctx):
    # The processes follow the sim's clock (SIM_CLOCK) in lockstep, unless --realtime: the sim
    # waits for every one before each tick (so a conductor's timeout in sim seconds never races a
    # computation), a tick is 10 steps of 5 ms at every rate (so the rate changes nothing), and the
    # sim holds its clock until the launch's conductor (its last process) runs, so that all start
    # at the same sim moment.
    clock, hold_viraal, hold_setup = [f"sim_rate={args.sim_rate}"], [], []
    if not args.realtime:
        clock += ["sim_time=1", "lockstep=1", "steps_per_tick=10"]
        hold_viraal, hold_setup = ["hold_for=scenario"], ["hold_for=setup"]
    # The run id seeds the alignments: from the seed, so a study is repeatable (not from the clock).
    run_id = args.run_id or f"study-s{args.seed}"
    quiet_build(ctx, ["testbed", *(bands_verb.BINARIES if args.bands or args.sensitivity else [])])
    steps = [("viraal", k) for k in range(1, args.users + 1)]
    for k in range(1, args.setup_users + 1):
        steps.append(("setup", k))
        if args.registration_share:
            steps.append(("setup-truth", k))
    progress = Progress(ctx.console, "study:", len(steps) + 1 + (bands_verb.STEPS if args.bands else 0) +
                        (sensitivity_verb.count() if args.sensitivity else 0))
    # The study's folder holds every user's run folder (viraal-u<k>, setup-u<k>, setup-truth-u<k>),
    # each with its own provenance record and its output (<name>.log) beside the study's files.
    study_dir = new_run_dir(ctx, "study-")
    if args.settings:
        # Checked once before the first user (and written into every user's run folder by its launch).
        try:
            write_settings(ctx, os.path.join(study_dir, "settings"), args.settings)
        except Failure:
            shutil.rmtree(study_dir, ignore_errors=True)
            raise Failure("study: the settings were refused (above); nothing was started", 2)
    provenance(ctx, "start", study_dir, "--kind", "study", "--setting", f"users={args.users}",
               "--setting", f"trials={args.trials}", "--setting", f"setup_users={args.setup_users}",
               "--setting", f"targets={args.targets}", "--setting", f"seed={args.seed}", "--setting", f"run_id={run_id}",
               "--setting", f"registration_share={int(args.registration_share)}", "--setting", f"sim_rate={args.sim_rate}",
               "--setting", f"realtime={int(args.realtime)}", "--setting", f"bands={args.bands}",
               "--setting", f"sensitivity={args.sensitivity}")
    ctx.say(f"study: {len(steps)} launches in {ctx.rel(study_dir)}/ (each one's output in <name>.log there)")
    tables_args, runs = ["--seed", str(args.seed)], []
    for kind, k in steps:
        user_seed = args.seed + k - 1
        name = f"{kind}-u{k}"
        if kind == "viraal":
            progress.show(f"ViRAAl user u{k} of {args.users}, {args.trials} trials per mode")
            # A safety limit that grows with the trials (a trial takes about a second here).
            duration, launch_file = 600 + 2 * 20 * args.trials, ctx.run_launch
            launch_args = [f"user_seed={user_seed}", f"trials={args.trials}", f"run_id={run_id}-u{k}", *clock,
                           *hold_viraal]
            runs.append(f"run:{name}")
            listed = f"u{k} {name} user_seed={user_seed}"
        else:
            truth = kind == "setup-truth"
            progress.show(f"set-up user u{k} of {args.setup_users}" + (" with the true registration" if truth else
                                                                       f", 3 modes x {args.targets} target(s)"))
            # A set-up takes 5-15 s here, an alignment of three trials a few seconds.
            duration, launch_file = 300 + 300 * args.targets, os.path.join(ctx.root, "scripts", "launch", "setup.yaml")
            # The user's patient (the design's draw from the seed): the sim collides with the
            # patient the targets were planned for; orbed-setup reads the same scene.
            draw = subprocess.run([os.path.join(ctx.bin, "orbed-design"), "draw", "--user-seed", str(user_seed),
                                   "--targets", str(args.targets)], capture_output=True, text=True)
            if draw.returncode != 0:
                raise Failure(f"study: orbed-design draw for user u{k} failed: {draw.stderr.strip()}")
            scene = json.loads(draw.stdout)["scene"]
            launch_args = [f"user=u{k}", f"user_seed={user_seed}", f"setup_targets={args.targets}", f"scene={scene}"]
            if truth:
                # The same person and targets, headset modes only, with the true registration
                # instead of the alignments: what a perfect registration would leave of the error.
                launch_args += ["setup_modes=ar_reflective,ar", "setup_registration=truth"]
            launch_args += [f"run_id={run_id}-{name}", *clock, *hold_setup]
            tables_args += ["--setup-truth" if truth else "--setup", f"run:{name}"]
            listed = f"{kind} u{k} {name} user_seed={user_seed}"
        log = os.path.join(study_dir, f"{name}.log")
        code, run_dir = launch_verb.launch(ctx, launch_file, duration=duration, args=launch_args, settings=args.settings,
                                           into=study_dir, name=name, log=log)
        if code != 0:
            show_failure(ctx.console, log)
            raise Failure(f"study: {name}'s run failed (exit code {code}; its output: {ctx.rel(log)}, "
                          f"its run folder: {ctx.rel(run_dir)})")
        with open(os.path.join(study_dir, "runs.txt"), "a") as f:
            f.write(listed + "\n")
        progress.step()
    tables_args += runs
    with open(os.path.join(study_dir, "tables_args.json"), "w") as f:
        json.dump(tables_args, f, indent=1)
    progress.show("the tables and the report")
    tables_argv = [os.path.join(study_dir, a[4:]) if a.startswith("run:") else a for a in tables_args]
    log = os.path.join(study_dir, "tables.log")
    if run_logged([os.path.join(ctx.bin, "orbed-study-tables"), "--out", study_dir, *tables_argv], log, ctx.console):
        show_failure(ctx.console, log)
        raise Failure("study: orbed-study-tables failed")
    analyze(ctx, study_dir, log)
    bands = None
    if args.bands:
        # The same seed as the study: its study 0 is this study's design run in-process.
        bands_dir = os.path.join(study_dir, "bands")
        os.makedirs(bands_dir, exist_ok=True)
        bands = bands_verb.simulate(ctx, bands_dir, args.bands, args.seed, 2, progress)
        progress.show("the report")
    sensitivity = None
    if args.sensitivity:
        sensitivity_dir = os.path.join(study_dir, "sensitivity")
        os.makedirs(sensitivity_dir, exist_ok=True)
        sensitivity = sensitivity_verb.simulate(ctx, sensitivity_dir, args.sensitivity, args.seed, 2, progress)
        progress.show("the report")
    if args.setup_users > 0 or args.bands or args.sensitivity:
        if run_logged(["/usr/bin/python3", ctx.script("report.py"), study_dir], log, ctx.console):
            show_failure(ctx.console, log)
            raise Failure("study: the report failed")
    progress.done()
    try:
        whole = drops(ctx, study_dir)
    except (OSError, ValueError, KeyError, subprocess.CalledProcessError) as e:
        raise Failure(f"study: a run folder has no readable manifest.json or log ({e})")
    # The tables as orbed-study-tables and the analysis printed them: the results, once.
    with open(log, errors="replace") as f:
        ctx.console.results(f.read())
    mode = ", wall clock" if args.realtime else ", on the sim clock in lockstep"
    ctx.say(f"study: {round(progress.elapsed())} s of wall time at sim rate {args.sim_rate}{mode} "
            f"(the runs, the tables and the report); {whole}")
    if bands:
        bands_verb.say_summary(ctx, bands_dir, *bands)
    if sensitivity:
        sensitivity_verb.say_summary(ctx, sensitivity_dir, sensitivity)
    provenance(ctx, "finish", study_dir, "--exit-code", "0")
    ctx.say(f"study: files in {ctx.rel(study_dir)}/ (runs.txt lists each user's run folder; provenance.json says "
            f"what made them; check them with scripts/orbed verify {ctx.rel(study_dir)})")
    return 0
