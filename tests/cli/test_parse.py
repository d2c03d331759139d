"""scripts/orbed's command line (scripts/orbed_cli): each verb's --help, the typo suggestion, usage
errors (exit 2, one line, the verb's usage) before anything is built, --version, and the progress
line's text. Every run of scripts/orbed here points ORBED_BUILD_DIR, ORBED_ASAN_BUILD_DIR and
ORBED_LOGS_DIR at empty temporary folders and checks that they stay empty."""
import os
import re
import subprocess

import pytest

from orbed_cli import main as cli
from orbed_cli.output import format_progress, weighted_left

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ORBED = os.path.join(ROOT, "scripts", "orbed")


@pytest.fixture
def orbed(tmp_path):
    """Runs scripts/orbed with empty build and logs folders; asserts nothing was made in them."""
    folders = {name: tmp_path / name for name in ("build", "build-asan", "logs")}
    for folder in folders.values():
        folder.mkdir()
    env = dict(os.environ, ORBED_BUILD_DIR=str(folders["build"]), ORBED_ASAN_BUILD_DIR=str(folders["build-asan"]),
               ORBED_LOGS_DIR=str(folders["logs"]))

    def run(*argv):
        done = subprocess.run([ORBED, *argv], env=env, capture_output=True, text=True, timeout=60)
        for name, folder in folders.items():
            assert list(folder.iterdir()) == [], f"{' '.join(argv)} touched the {name} folder"
        return done
    return run


@pytest.mark.parametrize("verb", cli.VERBS)
def test_each_verb_has_its_own_help(orbed, verb):
    done = orbed(verb, "--help")
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith(f"usage: scripts/orbed {verb} ")
    assert "The two commands most people need" not in done.stdout  # not the global usage


def test_help_lists_every_verb(orbed):
    done = orbed("help")
    assert done.returncode == 0
    for verb in cli.VERBS:
        assert re.search(rf"^  {verb} ", done.stdout, re.M), verb
    assert orbed().returncode == 2  # no command: the usage, on stderr


def test_a_typo_is_answered_with_the_nearest_verb(orbed):
    done = orbed("stduy", "--users", "1")
    assert done.returncode == 2
    assert "unknown command 'stduy'; did you mean 'study'?" in done.stderr
    assert len(done.stderr.splitlines()) == 2  # the usage line and the message
    far = orbed("xyzzy")
    assert far.returncode == 2 and "unknown command 'xyzzy'" in far.stderr and "did you mean" not in far.stderr


@pytest.mark.parametrize("argv, message", [
    (["study", "--users"], "argument --users: expected one argument"),
    (["study", "--users", "abc"], "argument --users: must be a whole number 0..99, not 'abc'"),
    (["study", "--targets", "7"], "argument --targets: must be a whole number 1..6, not '7'"),
    (["study", "--bands", "x"], "argument --bands: must be a whole number 0..100000, not 'x'"),
    (["study", "--users", "0", "--setup-users", "0"], "--users 0 and --setup-users 0 leave nothing to run"),
    (["study", "--realtime"], "--realtime keeps the wall clock, so --sim-rate must be 1"),
    (["study", "--run-id", "a b"], "argument --run-id: must be 1-64 letters"),
    (["study", "--set", "novalue"], "argument --set: expected NAME=VALUE, not 'novalue'"),
    (["run", "--bogus"], "unrecognized arguments: --bogus"),
    (["run", "--duration-s", "-3"], "argument --duration-s: must be a positive number, not '-3'"),
    (["run", "--config", "/no/such/file.yaml"], "--config: no file /no/such/file.yaml"),
    (["launch", "/no/such/launch.yaml"], "no launch file /no/such/launch.yaml"),
    (["launch", "--arg", "novalue"], "argument --arg: expected NAME=VALUE, not 'novalue'"),
    (["replay"], "the following arguments are required: LOG"),
    (["replay", "/no/such.lcmlog"], "no log /no/such.lcmlog"),
    (["replay", "x.lcmlog", "--speed", "fast"], "argument --speed: must be a positive number, not 'fast'"),
    (["sweep", "--only", "nothing"], "argument --only: invalid choice: 'nothing'"),
    (["sweep", "--trials", "0"], "argument --trials: must be a whole number 1..9999, not '0'"),
    (["fuzz", "0"], "argument SECONDS: must be a whole number 1..1000000000, not '0'"),
    (["scale", "--grid", "2by2"], "argument --grid: expected AxH,... (e.g. 1x1,2x2), not '2by2'"),
    (["load", "--factor", "nan"], "argument --factor: must be a positive number, not 'nan'"),
    (["study", "--sensitivity", "x"], "argument --sensitivity: must be a whole number 0..10000, not 'x'"),
    (["sensitivity", "--studies", "0"], "argument --studies: must be a whole number 1..10000, not '0'"),
    (["bands", "--studies", "0"], "argument --studies: must be a whole number 1..100000, not '0'"),
    (["bands", "--threads", "x"], "argument --threads: must be a whole number 1..64, not 'x'"),
    (["fit", "--depth-bias", "a,b"], "argument --depth-bias: expected finite numbers separated by commas, not 'a,b'"),
    (["fit", "--log-sigma", "0.1,nan"], "argument --log-sigma: expected finite numbers separated by commas, not '0.1,nan'"),
    (["verify"], "the following arguments are required: RUN"),
    (["verify", "/no/such/run"], "no run folder /no/such/run"),
    (["export"], "the following arguments are required: LOG"),
    (["export", "/no/such.lcmlog"], "no log /no/such.lcmlog"),
    (["export", "x.lcmlog", "--csv", "--mcap"], "argument --mcap: not allowed with argument --csv"),
    (["export", "x.lcmlog", "--from-s", "-1"], "argument --from-s: must be a number >= 0, not '-1'"),
    (["join"], "which command?"),
    (["deputy"], "the following arguments are required: NAME"),
    (["spy", "--log"], "argument --log: expected one argument"),
    (["test", "--bogus"], "unrecognized arguments: --bogus"),
    (["--quiet", "--verbose", "test"], "--quiet and --verbose exclude each other"),
])
def test_usage_errors_exit_2_with_one_line_and_the_verbs_usage(orbed, argv, message):
    done = orbed(*argv)
    assert done.returncode == 2, done.stderr
    assert done.stdout == ""
    errors = [line for line in done.stderr.splitlines() if "error:" in line]
    assert len(errors) == 1, done.stderr
    assert message in errors[0]
    assert done.stderr.startswith("usage: scripts/orbed ")
    verb = next(a for a in argv if not a.startswith("-"))
    assert done.stderr.startswith(f"usage: scripts/orbed {verb} ")


def test_version_names_the_project_version_and_the_commit(orbed):
    done = orbed("--version")
    assert done.returncode == 0
    with open(os.path.join(ROOT, "CMakeLists.txt")) as f:
        version = re.search(r"project\(orbed VERSION ([0-9.]+)", f.read()).group(1)
    head = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short=12", "HEAD"], capture_output=True, text=True)
    commit = head.stdout.strip() if head.returncode == 0 else "unknown"
    # The same line as every orbed executable's --version (base/command_line.h).
    assert re.fullmatch(r"orbed %s \(commit %s(, modified)?\)\n" % (re.escape(version), re.escape(commit)),
                        done.stdout), done.stdout


def test_global_flags_go_before_or_after_the_verb():
    args = cli.parse_args(["--quiet", "study", "--users", "2"])
    assert (args.verb, args.quiet, args.verbose, args.users) == ("study", True, False, 2)
    args = cli.parse_args(["study", "--bands", "20"])
    assert (args.bands, args.seed) == (20, 1)
    assert cli.parse_args(["study"]).bands == 0
    args = cli.parse_args(["study", "--verbose"])
    assert (args.quiet, args.verbose, args.users, args.setup_users, args.trials) == (False, True, 4, 8, 10)


def test_settings_keep_their_order():
    args = cli.parse_args(["run", "--set", "a.b=1", "--config", "x.yaml", "--set", "a.b=2"])
    assert args.settings == [("--set", "a.b=1"), ("--config", "x.yaml"), ("--set", "a.b=2")]


def test_the_progress_line():
    # 3 of 12 steps in 90 s: 30 s a step, 9 steps left, about 270 s = 4m 30s.
    assert format_progress("study:", 3, 12, 90) == "study: 3/12, 1m 30s elapsed, about 4m 30s left"
    # 1 of 4 in 20 s: 60 s left.
    assert format_progress("sweep: point", 1, 4, 20) == "sweep: point 1/4, 20 s elapsed, about 1m 00s left"
    assert format_progress("test:", 0, 5, 2) == "test: 0/5, 2 s elapsed, no estimate yet"
    assert format_progress("test:", 5, 5, 7384) == "test: 5/5, 2h 03m elapsed, done"
    # With the steps' weights known (tests by their recorded seconds): 30 of 120 weighed seconds done
    # in 20 s leave 90 at that pace, 60 s; the count (1 of 4) would have said the same only by chance.
    assert weighted_left(20, 30, 90) == 60
    assert weighted_left(5, 0, 90) is None
    assert format_progress("test:", 1, 4, 20, weighted_left(20, 30, 90)) == "test: 1/4, 20 s elapsed, about 1m 00s left"
    # Two long tests left after 150 quick ones: the count says seconds, the weights say minutes.
    assert format_progress("test:", 150, 152, 75) == "test: 150/152, 1m 15s elapsed, about 1 s left"
    assert format_progress("test:", 150, 152, 75, weighted_left(75, 75, 120)) == \
        "test: 150/152, 1m 15s elapsed, about 2m 00s left"
