"""deputy: on another machine, what launches with --lan place on host NAME."""
import os
import subprocess

from .netns import LAN_URL
from .paths import need_binaries

HELP = "on another machine: run what launches with --lan place on host NAME"
DESCRIPTION = """On another machine: run what launches with --lan place on host NAME (orbed-launch
--deputy NAME, host network, ttl=1); Ctrl-C stops it and what it runs."""


def configure(p):
    p.add_argument("name", metavar="NAME", help="this machine's host name in the launch files")


def run(args, ctx):
    need_binaries(ctx)
    ctx.say(f"deputy {args.name}: host network, ttl=1; runs what a launch with --lan places on host {args.name} "
            f"(run folders in {ctx.logs})")
    env = dict(os.environ, ORBED_LCM_URL=LAN_URL)
    return subprocess.run([os.path.join(ctx.bin, "orbed-launch"), "--deputy", args.name, "--log-root", ctx.logs],
                          env=env).returncode
