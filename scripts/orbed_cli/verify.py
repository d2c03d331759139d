"""verify: a run folder against its provenance record (scripts/provenance.py verify)."""
import os
import subprocess

from .paths import need_binaries

HELP = "check a run folder against its provenance.json; exit code 1 if anything differs"
DESCRIPTION = """Check a run folder against its provenance.json: every output's SHA-256, the configuration as
the tree has it now, a study's tables made again from its users' run folders; exit code 1 if any
differs."""


def configure(p):
    p.add_argument("run_dir", metavar="RUN", help="a folder under logs/ with a provenance.json")


def check(args, parser):
    if not os.path.isdir(args.run_dir):
        parser.error(f"no run folder {args.run_dir}")
    if not os.path.isfile(os.path.join(args.run_dir, "provenance.json")):
        parser.error(f"{args.run_dir} has no provenance.json (made before provenance records, or not a run folder)")


def run(args, ctx):
    need_binaries(ctx)
    return subprocess.run(["/usr/bin/python3", ctx.script("provenance.py"), "verify", args.run_dir,
                           "--bin", ctx.bin]).returncode
