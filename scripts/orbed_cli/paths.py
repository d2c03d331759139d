"""Where things are (the environment's ORBED_* folders, or the defaults beside the checkout), the
Debian packages orbed needs (setup), and the build (cmake; one at a time per build folder)."""
import fcntl
import os
import re
import shutil
import subprocess

from .output import Failure, Progress, run_logged, show_failure

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# Debian packages the project needs (build, run, test, inspect).
PACKAGES = """
  cmake g++ make pkg-config git ccache lld
  liblcm-dev liblcm-bin liblcm-java libjchart2d-java default-jdk-headless default-jre
  libeigen3-dev libopencv-dev liburdfdom-dev libtinyxml-dev liburdfdom-tools libbullet-dev libfcl-dev
  libyaml-cpp-dev nlohmann-json3-dev libcli11-dev libssl-dev libopenigtlink-dev openigtlink-examples libwebsocketpp-dev libasio-dev
  libgtest-dev libbenchmark-dev
  libavcodec-dev libavutil-dev
  iproute2 util-linux procps python3 python3-matplotlib python3-yaml python3-pytest python3-scipy python3-statsmodels python3-pandas python3-opencv xvfb xauth x11-utils clang-format clang libclang-rt-14-dev
  chromium
""".split()
RMEM_WANTED = 16777216  # LCM image traffic wants a large UDP receive buffer


def version():
    """The version line every orbed program prints (base/command_line.h): "orbed X.Y.Z (commit
    <12 hex>)", with ", modified" when tracked files differ from the commit; "unknown" outside git."""
    with open(os.path.join(ROOT, "CMakeLists.txt")) as f:
        found = re.search(r"project\(\s*orbed\s+VERSION\s+([0-9.]+)", f.read())
    commit = "unknown"
    head = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short=12", "HEAD"], capture_output=True, text=True)
    if head.returncode == 0 and head.stdout.strip():
        commit = head.stdout.strip()
        diff = subprocess.run(["git", "-C", ROOT, "diff", "--quiet", "HEAD", "--"], capture_output=True)
        if diff.returncode != 0:
            commit += ", modified"
    return f"orbed {found.group(1) if found else 'unknown'} (commit {commit})"


class Context:
    """One invocation: the folders (environment or defaults), the console and the command line as
    given (recorded in every provenance record)."""

    def __init__(self, console, command_line):
        env = os.environ
        self.console, self.command_line = console, command_line
        self.root = ROOT
        self.build_dir = env.get("ORBED_BUILD_DIR") or os.path.join(ROOT, "build")
        self.bin = os.path.join(self.build_dir, "bin")
        self.asan_build_dir = env.get("ORBED_ASAN_BUILD_DIR") or os.path.join(ROOT, "build-asan")
        self.jobs = env.get("ORBED_JOBS") or "2"
        self.logs = env.get("ORBED_LOGS_DIR") or os.path.join(ROOT, "logs")  # every run folder is made here
        self.netns_dir = os.path.join(self.logs, ".netns")
        self.default_launch = os.path.join(ROOT, "scripts", "launch", "testbed.yaml")
        self.run_launch = os.path.join(ROOT, "scripts", "launch", "viraal.yaml")

    def script(self, name):
        return os.path.join(ROOT, "scripts", name)

    def rel(self, path):
        """PATH relative to the checkout when inside it (for messages)."""
        path = str(path)
        return path[len(ROOT) + 1:] if path.startswith(ROOT + "/") else path

    def say(self, message):
        self.console.say(message)


def as_root(ctx, argv, **kwargs):
    if os.getuid() == 0:
        return subprocess.run(argv, **kwargs)
    if shutil.which("sudo"):
        return subprocess.run(["sudo", *argv], **kwargs)
    raise Failure(f"need root for: {' '.join(argv)} (run as root or install sudo)")


def setup(ctx):
    """Installs the missing Debian packages and raises net.core.rmem_max where allowed."""
    missing = []
    for pkg in PACKAGES:
        done = subprocess.run(["dpkg-query", "-W", "-f=${Status}", pkg], capture_output=True, text=True)
        if "install ok installed" not in done.stdout:
            missing.append(pkg)
    if not missing:
        ctx.say(f"setup: all {len(PACKAGES)} packages present")
    else:
        ctx.say(f"setup: installing {len(missing)} packages: {' '.join(missing)}")
        if as_root(ctx, ["apt-get", "update", "-qq"]).returncode != 0:
            raise Failure("setup: apt-get update failed")
        if as_root(ctx, ["env", "DEBIAN_FRONTEND=noninteractive", "apt-get", "install", "-y", "-qq",
                         "--no-install-recommends", *missing], stdout=subprocess.DEVNULL).returncode != 0:
            raise Failure("setup: apt-get install failed")
        ctx.say("setup: packages installed")
    found = subprocess.run(["sysctl", "-n", "net.core.rmem_max"], capture_output=True, text=True)
    rmem = int(found.stdout.strip()) if found.returncode == 0 and found.stdout.strip().isdigit() else 0
    if rmem < RMEM_WANTED:
        raised = as_root(ctx, ["sysctl", "-q", "-w", f"net.core.rmem_max={RMEM_WANTED}"],
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        if raised.returncode == 0:
            ctx.say(f"setup: net.core.rmem_max raised from {rmem} to {RMEM_WANTED}")
        else:
            ctx.say(f"setup: cannot raise net.core.rmem_max ({rmem}); large LCM messages may be dropped")


def cmake_build(ctx, build_dir, configure_argv, targets=(), log=None, env=None, what="build"):
    """Configures BUILD_DIR once (configure_argv) and compiles TARGETS (default everything), one
    build at a time per folder (commands started together take turns on a lock file). With LOG,
    the compiler's output goes there and one progress line follows cmake's [ NN%]; a failure shows
    the log's tail. Returns the seconds it took."""
    os.makedirs(build_dir, exist_ok=True)
    started = Progress(ctx.console, f"{what}: percent", 100)
    with open(os.path.join(build_dir, ".orbed-build.lock"), "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not os.path.isfile(os.path.join(build_dir, "CMakeCache.txt")):
            ctx.say(f"{what}: configuring {ctx.rel(build_dir)}")
            done = subprocess.run(configure_argv, stdout=subprocess.DEVNULL, env=env)
            if done.returncode != 0:
                raise Failure(f"{what}: cmake could not configure {ctx.rel(build_dir)}")
        argv = ["cmake", "--build", build_dir, f"-j{ctx.jobs}"]
        for t in targets:
            argv += ["--target", t]
        ctx.say(f"{what}: compiling {' '.join(targets) or 'everything'} with -j{ctx.jobs}")
        if log is None:
            code = subprocess.run(argv).returncode
        else:
            if os.path.exists(log):
                os.remove(log)

            def on_line(line):
                m = re.match(r"\[\s*(\d+)%\]", line)
                # On a terminal every percent; otherwise every tenth.
                if m and (int(m.group(1)) // (1 if ctx.console.tty else 10)) != started.k // (1 if ctx.console.tty else 10):
                    started.k = int(m.group(1))
                    started.show()
            code = run_logged(argv, log, ctx.console, on_line=on_line)
            if code != 0:
                show_failure(ctx.console, log)
            else:
                started.done()
    if code != 0:
        raise Failure(f"{what}: the build failed (exit code {code})", code)
    return started.elapsed()


def build(ctx, targets=(), log=None):
    """setup + the release build of TARGETS (default everything; `testbed` the testbed's
    processes and tools)."""
    setup(ctx)
    return cmake_build(ctx, ctx.build_dir, ["cmake", "-S", ROOT, "-B", ctx.build_dir, "-DCMAKE_BUILD_TYPE=Release"],
                       targets, log=log)


def quiet_build(ctx, targets):
    """A build inside long work: compiler output into the build folder's build.log."""
    os.makedirs(ctx.build_dir, exist_ok=True)
    return build(ctx, targets, log=os.path.join(ctx.build_dir, "build.log"))


def need_binaries(ctx):
    if not os.access(os.path.join(ctx.bin, "orbed-launch"), os.X_OK):
        build(ctx, ["testbed"])
