"""bench: the Google Benchmark programs (build/bench/*), each in a private network namespace."""
import os
import subprocess

from .netns import netns_exec
from .output import Failure
from .paths import need_binaries

HELP = "build and run the Google Benchmark programs, each in a private network namespace"
DESCRIPTION = """Build and run the Google Benchmark programs (build/bench/*), each in a private network
namespace; ORBED_BENCH_SECONDS shortens load runs."""


def configure(p):
    p.add_argument("names", nargs="*", metavar="NAME", help="benchmark programs (default all)")


def run(args, ctx):
    need_binaries(ctx)
    if subprocess.run(["cmake", "--build", ctx.build_dir, f"-j{ctx.jobs}"], stdout=subprocess.DEVNULL).returncode:
        raise Failure("bench: the build failed")
    folder = os.path.join(ctx.build_dir, "bench")
    names = args.names or sorted(n for n in (os.listdir(folder) if os.path.isdir(folder) else [])
                                 if os.access(os.path.join(folder, n), os.X_OK) and
                                 os.path.isfile(os.path.join(folder, n)))
    if not names:
        raise Failure(f"bench: no benchmark programs in {folder}")
    env = dict(os.environ, ORBED_BIN_DIR=ctx.bin, ORBED_SOURCE_DIR=ctx.root)
    for name in names:
        exe = os.path.join(folder, name)
        if not os.access(exe, os.X_OK):
            raise Failure(f"bench: no {exe}")
        ctx.say(f"bench: {name}")
        code = netns_exec(ctx, [exe], env=env)
        if code:
            return code
    return 0
