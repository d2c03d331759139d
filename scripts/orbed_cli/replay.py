"""replay: a log (lcm-logplayer) into a fresh private namespace, LCM's player window, or the host
network."""
import csv
import os
import subprocess
import tempfile

from . import checks
from .netns import LAN_URL, netns_exec
from .output import Failure
from .paths import need_binaries
from .runs import utc_stamp
from .spy import classpath

HELP = "play a log into a fresh private namespace (--gui: LCM's log player window)"
DESCRIPTION = """Play a log (lcm-logplayer) into a fresh private namespace; --gui in LCM's log player window
(pause, seek, speed, channel filters); --lan on the host network (ttl=1), for a bridge started on
the host; --sim-rate plays a log recorded faster than real time at the pace of its sim time (speed
X / R, R from its SIM_CLOCK)."""


def configure(p):
    p.add_argument("log", metavar="LOG", help="an .lcmlog (logs/<run>/<file>.lcmlog)")
    p.add_argument("--speed", type=checks.positive, default="1", metavar="X", help="times real time (default 1)")
    p.add_argument("--sim-rate", action="store_true", help="at the pace of the log's sim time")
    p.add_argument("--channels", default=".*", metavar="REGEX", help="only these channels")
    p.add_argument("--gui", action="store_true", help="LCM's log player window")
    p.add_argument("--lan", action="store_true", help="on the host network (ttl=1)")


def check(args, parser):
    if not os.path.isfile(args.log):
        parser.error(f"no log {args.log}")


def sim_rate_of(ctx, log):
    """The sim rate R a log was recorded at (its first SIM_CLOCK message)."""
    need_binaries(ctx)
    with tempfile.TemporaryDirectory() as tmp:
        done = subprocess.run([os.path.join(ctx.bin, "orbed-log"), "export", "--channels", "SIM_CLOCK", log, tmp],
                              stdout=subprocess.DEVNULL)
        if done.returncode != 0:
            raise Failure(f"replay --sim-rate: cannot read {log}")
        rate = ""
        path = os.path.join(tmp, "SIM_CLOCK.csv")
        if os.path.isfile(path):
            with open(path) as f:
                rows = list(csv.reader(f))
            rate = rows[1][2] if len(rows) > 1 and len(rows[1]) > 2 else ""
    if not rate.isdigit() or int(rate) < 1:
        raise Failure(f"replay --sim-rate: {log} has no SIM_CLOCK (recorded before the sim clock, or without the sim)")
    return int(rate)


def run(args, ctx):
    speed, log = args.speed, args.log
    if args.sim_rate:
        rate = sim_rate_of(ctx, log)
        speed = f"{float(speed) / rate:.6g}"
        ctx.say(f"replay: the log was recorded at sim rate {rate}: played at {speed}x, the pace of its sim time")
    os.makedirs(ctx.netns_dir, exist_ok=True)
    fd, pidfile = tempfile.mkstemp(prefix=f"replay-{utc_stamp()}-", suffix=".pid", dir=ctx.netns_dir)
    os.close(fd)
    if args.gui:
        # LCM's log player window, started with `java -cp` as lcm-spy is: Debian's
        # lcm-logplayer-gui launcher passes -Xincgc, which Java 17 refuses.
        if not os.environ.get("DISPLAY"):
            os.remove(pidfile)
            raise Failure("replay --gui: the player is a window and DISPLAY is not set "
                          "(try: xvfb-run -a scripts/orbed replay --gui LOG)")
        player = ["java", "-Djava.net.preferIPv4Stack=true", "-Xmx256m", "-cp", classpath(ctx), "lcm.logging.LogPlayer"]
        if args.channels != ".*":
            player += ["--invert-filter", "--filter", args.channels]
        if speed != "1":
            ctx.say("replay --gui: the window sets the speed (its faster / slower buttons); --speed is ignored")
        ctx.say(f"replay --gui: {log} in LCM's log player, in a fresh namespace; watch it with: scripts/orbed spy")
        return netns_exec(ctx, [*player, log], pidfile=pidfile)
    if args.lan:
        os.remove(pidfile)
        # On the host's network, as `launch --lan`: for a bridge (Foxglove, Slicer) started on the host.
        ctx.say(f"replay: {log} at {speed}x, channels /{args.channels}/, on the host network (ttl=1)")
        return subprocess.run(["lcm-logplayer", "-l", LAN_URL, "-s", speed, "-e", args.channels, log]).returncode
    ctx.say(f"replay: {log} at {speed}x, channels /{args.channels}/, in a fresh namespace")
    ctx.say("replay: watch it with: scripts/orbed spy   (joins this namespace while it plays)")
    return netns_exec(ctx, ["lcm-logplayer", "-s", speed, "-e", args.channels, log], pidfile=pidfile)
