"""fuzz: every libFuzzer target (tests/fuzz) for SECONDS, through their ctest entries, then a table
of what each did (libFuzzer's final stats in build-asan/fuzz/reports/)."""
import os
import re
import shutil
import subprocess

from . import checks
from .paths import setup
from .test import build_asan

HELP = "build the sanitizer tree with the libFuzzer targets and run each for SECONDS"
DESCRIPTION = """Build the sanitizer tree with the libFuzzer targets (build-asan/) and run every target for
SECONDS each (default 60) from its seeds; prints executions, rate, peak memory and findings per
target."""


def configure(p):
    p.add_argument("seconds", nargs="?", type=checks.whole(1, 10**9), default=60, metavar="SECONDS",
                   help="per target (default 60)")


def table(folder):
    lines = [f"\n{'target':<20} {'executions':>12} {'exec/s':>9} {'peak RSS MB':>12}  result"]
    for name in sorted(os.listdir(folder)) if os.path.isdir(folder) else []:
        with open(os.path.join(folder, name), errors="replace") as f:
            text = f.read()
        stat = dict(re.findall(r"stat::(\w+):\s+(\d+)", text))
        runs = re.search(r"Done (\d+) runs in (\d+) second", text)
        rate = int(runs.group(1)) / max(1, int(runs.group(2))) if runs else 0
        found = re.search(r"ERROR: libFuzzer: [^\n]*|==\d+==ERROR: [^\n]*|SUMMARY: [^\n]*", text)
        result = found.group(0)[:60] if found else "0 crashes, 0 leaks, 0 timeouts"
        lines.append(f"{name[:-4]:<20} {int(stat.get('number_of_executed_units', 0)):>12} {rate:>9.0f} "
                     f"{int(stat.get('peak_rss_mb', 0)):>12}  {result}")
    return "\n".join(lines)


def run(args, ctx):
    seconds = args.seconds
    setup(ctx)
    build_asan(ctx)
    shutil.rmtree(os.path.join(ctx.asan_build_dir, "fuzz", "reports"), ignore_errors=True)
    ctx.say(f"fuzz: every target for {seconds} s (about {seconds * 14 // 60 + 1} min)")
    env = dict(os.environ, ORBED_FUZZ_SECONDS=str(seconds))
    code = subprocess.run(["ctest", "-L", "fuzz", "--output-on-failure", "--timeout", str(seconds + 600)],
                          cwd=ctx.asan_build_dir, env=env).returncode
    ctx.console.results(table(os.path.join(ctx.asan_build_dir, "fuzz", "reports")))
    ctx.say(f"fuzz: new inputs in {ctx.rel(ctx.asan_build_dir)}/fuzz/corpus/, findings in "
            f"{ctx.rel(ctx.asan_build_dir)}/fuzz/crashes/")
    return code
