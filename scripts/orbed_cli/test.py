"""test: the release build and its suite (unit + integration + the CLI's pytest); --sanitize the
clang sanitizer + fuzz build and its suite; --quick only the tests labelled quick (the unit tests
and the CLI's pytest: what a developer runs while editing). The compiler's output goes to
BUILD/build.log and ctest's to BUILD/ctest.log; one progress line follows each, a failure shows the
log's tail; the summary says each suite's result line and times."""
import os
import re
import subprocess

from .output import Progress, run_logged, show_failure
from .paths import ROOT, build, cmake_build, setup

HELP = "build (release) and run its tests; --sanitize: the sanitizer build's; --quick: the quick ones"
DESCRIPTION = """Set up, build and run the release suite with ctest (unit tests, integration tests, the CLI's
pytest) and print its summary. --sanitize instead builds the sanitizer tree (clang, ASan + UBSan +
LSan, libFuzzer targets, build-asan/) and runs its suite. --quick runs only the tests labelled quick
(unit tests; no integration, Xvfb, Chromium or multi-process tests). -R REGEX passes a test filter
to ctest. .ci/run runs `test` and then `test --sanitize`."""


def configure(p):
    p.add_argument("--sanitize", action="store_true", help="the sanitizer + fuzz build (build-asan/) and its suite")
    p.add_argument("--quick", action="store_true", help="only the tests labelled quick")
    p.add_argument("-R", dest="regex", metavar="REGEX", help="only tests whose name matches REGEX (ctest -R)")


def build_asan(ctx, log=None):
    """The sanitizer build (cmake/OrbedSanitizers.cmake): the same tree with clang, RelWithDebInfo,
    -fsanitize=address,undefined, libFuzzer's coverage and the fuzz targets (tests/fuzz: ctest runs
    each briefly), no benchmarks. Any report fails the test that made it."""
    env = dict(os.environ, CC="clang", CXX="clang++")
    configure_argv = ["cmake", "-S", ROOT, "-B", ctx.asan_build_dir, "-DCMAKE_BUILD_TYPE=RelWithDebInfo",
                      "-DORBED_SANITIZE=address,undefined", "-DORBED_FUZZ=ON", "-DORBED_BENCHMARKS=OFF"]
    return cmake_build(ctx, ctx.asan_build_dir, configure_argv, log=log, env=env, what="sanitizer build")


def last_durations(build_dir, filters):
    """Each test ctest will run (ctest -N with the same filters) -> its duration [s] as ctest
    recorded it in earlier runs (Testing/Temporary/CTestCostData.txt: "name runs seconds" lines, the
    seconds averaged over the runs); tests not recorded get the median. {} when nothing is recorded
    (a fresh build)."""
    record = os.path.join(build_dir, "Testing", "Temporary", "CTestCostData.txt")
    seconds = {}
    try:
        with open(record) as f:
            for line in f:
                if line.startswith("---"):
                    break
                parts = line.split()
                if len(parts) == 3:
                    seconds[parts[0]] = float(parts[2])
    except (OSError, ValueError):
        return {}
    listed = subprocess.run(["ctest", "-N"] + filters, cwd=build_dir, capture_output=True, text=True)
    names = re.findall(r"^\s*Test\s+#\d+: (\S+)", listed.stdout, flags=re.M)
    if not seconds or not names:
        return {}
    known = sorted(seconds.values())
    median = known[len(known) // 2]
    return {name: seconds.get(name, median) for name in names}


def run_suite(ctx, build_dir, what, labels=None, regex=None):
    """ctest in BUILD_DIR (output in BUILD_DIR/ctest.log); returns (exit code, ctest's
    "N% tests passed" line or why there is none, seconds)."""
    log = os.path.join(build_dir, "ctest.log")
    if os.path.exists(log):
        os.remove(log)
    argv = ["ctest", "--output-on-failure", f"-j{ctx.jobs}"]
    if labels:
        argv += ["-L", labels]
    if regex:
        argv += ["-R", regex]
    ctx.say(f"test: ctest in {ctx.rel(build_dir)}{' -L ' + labels if labels else ''}{' -R ' + regex if regex else ''}")
    progress = Progress(ctx.console, f"test: {what}", 1)
    progress.weights = last_durations(build_dir, argv[3:])  # the estimate weighs each test by its recorded time
    failed = []

    def on_line(line):
        m = re.match(r"\s*(\d+)/(\d+) Test\s+#\d+: (\S+) .*?(Passed|\*\*\*|Failed|Not Run|Exception)?", line)
        if m:
            progress.n, progress.k = int(m.group(2)), int(m.group(1))
            if progress.weights:
                progress.done_weight += progress.weights.get(m.group(3), 0.0)
            if "Passed" not in line:
                failed.append(m.group(3))
            progress.show(f"{m.group(3)}" + (f"; failed: {', '.join(failed)}" if failed else ""))
    code = run_logged(argv, log, ctx.console, on_line=on_line, cwd=build_dir)
    with open(log, errors="replace") as f:
        lines = [x.strip() for x in f if re.search(r"tests passed|No tests were found", x)]
    line = lines[-1] if lines else f"ctest failed (exit code {code})"
    progress.done(line)
    if code != 0:
        show_failure(ctx.console, log, 60)
    return code, line, round(progress.elapsed())


def run(args, ctx):
    labels = "quick" if args.quick else None
    if args.sanitize:
        setup(ctx)
        built = build_asan(ctx, log=os.path.join(ctx.asan_build_dir, "build.log"))
        ctx.say(f"test: sanitizer build compiled in {round(built)} s")
        code, line, seconds = run_suite(ctx, ctx.asan_build_dir, "sanitizer suite", labels, args.regex)
        name, folder = "sanitizers", ctx.asan_build_dir
    else:
        os.makedirs(ctx.build_dir, exist_ok=True)
        built = build(ctx, log=os.path.join(ctx.build_dir, "build.log"))
        ctx.say(f"test: release build compiled in {round(built)} s")
        code, line, seconds = run_suite(ctx, ctx.build_dir, "release suite", labels, args.regex)
        name, folder = "release", ctx.build_dir
    ctx.console.results(f"test summary:\n  {name:<10} {ctx.rel(folder)}{' (quick)' if args.quick else ''}: "
                        f"{line} ({seconds} s; build {round(built)} s)")
    return code
