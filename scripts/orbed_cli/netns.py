"""Private network namespaces (scripts/netns-exec: loopback only, multicast on it) and the running
testbeds: logs/.netns/<NAME>.pid names a process inside each (launch-<run>, replay-<time>-<random>),
so that spy and join can enter its namespace (nsenter)."""
import os
import subprocess

from .output import Failure

LAN_URL = "udpm://239.255.76.67:7667?ttl=1"  # the host network, ttl=1: this LAN segment


def netns_exec(ctx, argv, pidfile=None, env=None, **kwargs):
    """Runs argv in a fresh private namespace; with PIDFILE, a process inside it is named there
    while it runs (removed after). Returns the exit code."""
    env = dict(os.environ if env is None else env)
    if pidfile:
        env["ORBED_NETNS_PIDFILE"] = pidfile
    try:
        return subprocess.run([ctx.script("netns-exec"), *argv], env=env, **kwargs).returncode
    finally:
        if pidfile and os.path.exists(pidfile):
            os.remove(pidfile)


def running_testbeds(ctx):
    """[(NAME, PID)] of the testbeds whose process is alive; stale pid files are removed."""
    found = []
    if not os.path.isdir(ctx.netns_dir):
        return found
    for name in sorted(os.listdir(ctx.netns_dir)):
        if not name.endswith(".pid"):
            continue
        path = os.path.join(ctx.netns_dir, name)
        try:
            with open(path) as f:
                pid = f.read().strip()
        except OSError:
            continue
        alive = pid.isdigit()
        if alive:
            try:
                os.kill(int(pid), 0)
            except ProcessLookupError:
                alive = False
            except PermissionError:
                pass
        if alive:
            found.append((name[:-len(".pid")], pid))
        else:
            try:
                os.remove(path)
            except OSError:
                pass
    return found


def testbed_pid(ctx, want):
    """The namespace pid of the testbed WANT (a unique part of its name will do), or of the only
    one running; with several and no WANT it says which there are."""
    running = running_testbeds(ctx)
    if not running:
        raise Failure("no running testbed found (start one with scripts/orbed launch)")
    chosen = [r for r in running if want in r[0]] if want else running
    if not chosen:
        raise Failure(f"no running testbed matches '{want}'; running: {' '.join(n for n, _ in running)}")
    if len(chosen) > 1:
        raise Failure(f"several testbeds are running; say which with --run NAME: {' '.join(n for n, _ in chosen)}")
    return chosen[0][1]


def join_testbed(ctx, want, argv):
    """Runs argv in the network namespace of the running testbed WANT; returns its exit code."""
    pid = testbed_pid(ctx, want)
    ctx.say(f"joining the testbed's network namespace (pid {pid})")
    if subprocess.run(["nsenter", "--target", pid, "--net", "true"], stderr=subprocess.DEVNULL).returncode == 0:
        return subprocess.run(["nsenter", "--target", pid, "--net", *argv]).returncode
    return subprocess.run(["nsenter", "--target", pid, "--user", "--net", "--preserve-credentials", *argv]).returncode
