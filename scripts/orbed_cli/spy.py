"""spy: lcm-spy with orbed's types, live (joined to a running testbed) or over a replayed log."""
import os
import subprocess

from .netns import join_testbed
from .output import Failure
from .paths import build

HELP = "lcm-spy with orbed's types: live, or over a log replayed in a fresh namespace"
DESCRIPTION = """lcm-spy with orbed's types: live, joined to the running testbed's namespace (--run NAME, or
part of it, when several run), or over a log replayed (looping) in a fresh namespace (--log FILE).
lcm-spy is a window: DISPLAY must be set (try: xvfb-run -a scripts/orbed spy ...)."""


def configure(p):
    p.add_argument("--log", metavar="FILE", help="an .lcmlog to replay (looping)")
    p.add_argument("--run", metavar="NAME", help="the running testbed (a unique part of its name will do)")


def check(args, parser):
    if args.log and not os.path.isfile(args.log):
        parser.error(f"no log {args.log}")


def classpath(ctx):
    """lcm.jar, jchart2d and orbed's types (built when missing)."""
    jar = os.path.join(ctx.build_dir, "share", "java", "orbed_lcmtypes.jar")
    if not os.path.isfile(jar):
        build(ctx, ["orbed_lcmtypes_jar"])
    return f"/usr/share/java/lcm.jar:/usr/share/java/jchart2d.jar:{jar}"


def run(args, ctx):
    if not os.environ.get("DISPLAY"):
        raise Failure("spy: lcm-spy is a window and DISPLAY is not set (try: xvfb-run -a scripts/orbed spy ...)")
    java = ["java", "-Djava.net.preferIPv4Stack=true", "-Xmx256m", "-cp", classpath(ctx), "lcm.spy.Spy"]
    if args.log:
        ctx.say(f"spy: replaying {args.log} in a fresh namespace (looping) with lcm-spy")
        loop = ('(while true; do lcm-logplayer "$1" >/dev/null 2>&1 || exit; done) & player=$!\n'
                'trap "kill $player 2>/dev/null" EXIT\nshift; "$@"')
        return subprocess.run([ctx.script("netns-exec"), "bash", "-c", loop, "_", args.log, *java]).returncode
    return join_testbed(ctx, args.run, java)
