"""setup: the Debian packages orbed needs, and net.core.rmem_max (paths.setup)."""
from .paths import setup

HELP = "install the Debian packages orbed needs (apt-get) and raise net.core.rmem_max"
DESCRIPTION = """Install the Debian packages orbed needs (apt-get; as root or via sudo) and raise
net.core.rmem_max where allowed; a second run does nothing."""


def configure(p):
    pass


def run(args, ctx):
    setup(ctx)
    return 0
