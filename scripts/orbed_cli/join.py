"""join: a command on the running testbed's bus (its private namespace)."""
import argparse

from .netns import join_testbed

HELP = "run CMD on the running testbed's bus (in its namespace)"
DESCRIPTION = """Run CMD on the running testbed's bus (in its network namespace), e.g.
build/bin/orbed-drake-viewer, or Drake's Meldis viewer; --run NAME (or part of it) when several run."""


def configure(p):
    p.add_argument("--run", metavar="NAME", help="the testbed (a unique part of its name will do)")
    p.add_argument("command", nargs=argparse.REMAINDER, metavar="CMD...", help="the command and its arguments")


def check(args, parser):
    if not args.command:
        parser.error("which command? (scripts/orbed join [--run NAME] CMD...)")


def run(args, ctx):
    return join_testbed(ctx, args.run, args.command)
