"""scripts/orbed: the verbs, the global flags and the dispatch.

parse_args(argv) only parses (types and ranges; nothing on disk is looked at), so any command line
can be checked anywhere (tests/cli/test_readme.py parses README's). main(argv) parses, then runs the
verb's check (files that must exist, combinations) and only then its work: a usage error never
waits for a build. Usage errors exit 2 with the verb's usage and one line; a failure exits 1 (or
the failing child's code) with `orbed: error: ...`."""
import argparse
import difflib
import importlib
import sys

from .output import Console, Failure

VERBS = ["setup", "build", "launch", "run", "deputy", "test", "spy", "join", "replay", "bench", "fuzz", "load",
         "scale", "study", "bands", "sensitivity", "sweep", "fit", "verify", "export"]
PROG = "scripts/orbed"


def module(verb):
    return importlib.import_module(f".{verb}", __package__)


def global_flags():
    p = argparse.ArgumentParser(add_help=False)
    g = p.add_argument_group("output")
    g.add_argument("-q", "--quiet", action="store_true", help="only results and errors")
    g.add_argument("-v", "--verbose", action="store_true", help="show the children's output (long work)")
    return p


def verb_parser(verb):
    m = module(verb)
    p = argparse.ArgumentParser(prog=f"{PROG} {verb}", description=m.DESCRIPTION, parents=[global_flags()],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    m.configure(p)
    p.set_defaults(verb=verb)
    return p


def usage():
    width = max(len(v) for v in VERBS)
    lines = [f"usage: {PROG} [--quiet | --verbose] [--version] COMMAND [ARGS]", "",
             "The two commands most people need:",
             f"  {'run':<{width}}  {module('run').HELP}",
             f"  {'test':<{width}}  {module('test').HELP}", "", "Everything else:"]
    lines += [f"  {v:<{width}}  {module(v).HELP}" for v in VERBS if v not in ("run", "test")]
    lines += ["", f"`{PROG} COMMAND --help` says more about each.",
              "",
              "SETTINGS, for run, launch, study and sweep: --config FILE (a YAML file of sections of orbed's",
              "configuration files: user:, slam:, head_trajectory:, hmd: as in hmd_emulator/config/*.yaml,",
              "assistant: as in procs/assistant/assistant.yaml, for set-up runs) and --set KEY=VALUE (a dotted",
              "key of those, e.g. --set user.direct_view.depth_bias_fraction_std=0.03), both repeatable, later",
              "ones over earlier ones; checked before anything starts, written into the run folder (settings/)",
              "and recorded in provenance.json.",
              "",
              "Global flags: --quiet (results and errors only), --verbose (the children's output of long work",
              "on the terminal as well as in the run folder's log files), --version.",
              "Environment: ORBED_BUILD_DIR (default build/), ORBED_ASAN_BUILD_DIR (default build-asan/),",
              "ORBED_LOGS_DIR (where run folders are made; default logs/), ORBED_JOBS (default 2)."]
    return "\n".join(lines) + "\n"


def usage_error(message):
    sys.stderr.write(f"usage: {PROG} [--quiet | --verbose] [--version] COMMAND [ARGS]\n{PROG}: error: {message}\n")
    sys.exit(2)


def split_globals(argv):
    """(global flags, verb or None, the verb's arguments); --version and help handled here."""
    flags = []
    for i, arg in enumerate(argv):
        if arg in ("-q", "--quiet", "-v", "--verbose"):
            flags.append(arg)
        elif arg == "--version":
            from .paths import version
            sys.stdout.write(version() + "\n")
            sys.exit(0)
        elif arg in ("help", "-h", "--help"):
            if i + 1 < len(argv) and argv[i + 1] in VERBS:
                return flags, argv[i + 1], ["--help"]
            sys.stdout.write(usage())
            sys.exit(0)
        elif arg.startswith("-"):
            usage_error(f"unknown option '{arg}' (before the command)")
        else:
            return flags, arg, argv[i + 1:]
    return flags, None, []


def parse_args(argv):
    """The parsed command line (argparse.Namespace with verb, quiet, verbose and the verb's
    arguments); SystemExit(2) with a message on a usage error, SystemExit(0) for --help."""
    flags, verb, rest = split_globals(list(argv))
    if verb is None:
        sys.stderr.write(usage())
        sys.exit(2)
    if verb not in VERBS:
        near = difflib.get_close_matches(verb, VERBS, n=1)
        usage_error(f"unknown command '{verb}'" + (f"; did you mean '{near[0]}'?" if near else
                                                   f"; the commands: {', '.join(VERBS)}"))
    parser = verb_parser(verb)
    args = parser.parse_args(rest)
    args.quiet = args.quiet or "-q" in flags or "--quiet" in flags
    args.verbose = args.verbose or "-v" in flags or "--verbose" in flags
    if args.quiet and args.verbose:
        parser.error("--quiet and --verbose exclude each other")
    args.parser = parser
    return args


def main(argv):
    args = parse_args(argv)
    m = module(args.verb)
    if hasattr(m, "check"):
        m.check(args, args.parser)
    from .paths import Context
    console = Console(quiet=args.quiet, verbose=args.verbose)
    ctx = Context(console, [PROG, *argv])
    try:
        code = m.run(args, ctx)
    except Failure as e:
        console.error(str(e))
        return e.code
    except KeyboardInterrupt:
        console.error("interrupted")
        return 130
    return code or 0
