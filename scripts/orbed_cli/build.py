"""build: setup + cmake configure + compile (paths.build)."""
from .paths import build

HELP = "setup + cmake configure + build (binaries in build/bin)"
DESCRIPTION = """setup + cmake configure + build (binaries in build/bin); default everything, `build testbed`
only the testbed's processes and tools."""


def configure(p):
    p.add_argument("targets", nargs="*", metavar="TARGET", help="cmake targets (default everything)")


def run(args, ctx):
    build(ctx, args.targets)
    return 0
