"""What scripts/orbed says: messages on stderr ("orbed: ..."), errors, the one progress line of long
work, and child processes whose output goes to a log file.

Threading: Progress may be ticked from a timer thread (load) while the main thread waits for a
child; its writes take a lock. Everything else runs on the main thread."""
import subprocess
import sys
import threading
import time


class Failure(Exception):
    """A command that could not do its work: `orbed: error: MESSAGE`, exit code `code`."""

    def __init__(self, message, code=1):
        super().__init__(message)
        self.code = code


def clock(seconds):
    """Seconds as 45 s, 3m 07s or 1h 02m."""
    seconds = int(round(seconds))
    if seconds < 60:
        return f"{seconds} s"
    if seconds < 3600:
        return f"{seconds // 60}m {seconds % 60:02d}s"
    return f"{seconds // 3600}h {seconds % 3600 // 60:02d}m"


def format_progress(what, k, n, elapsed_s, left_s=None):
    """The progress line: WHAT k/n, elapsed, and an estimate of what is left: `left_s` where the
    caller knows better (weighted_left), else from the mean time of the k steps done
    ((n - k) * elapsed / k). Pure: tests/cli/test_parse.py checks it by hand."""
    line = f"{what} {k}/{n}, {clock(elapsed_s)} elapsed"
    if k >= n:
        return line + ", done"
    if left_s is not None:
        return line + f", about {clock(left_s)} left"
    if k == 0:
        return line + ", no estimate yet"
    return line + f", about {clock((n - k) * elapsed_s / k)} left"


def weighted_left(elapsed_s, done_weight, left_weight):
    """What is left of work whose steps weigh differently (a test suite: each test's last duration),
    at the pace so far: elapsed * left / done. None before any weight is done."""
    if done_weight <= 0:
        return None
    return elapsed_s * left_weight / done_weight


class Console:
    """Messages (stderr), the progress line, and whether children's output is shown (--verbose)
    or only messages are kept back (--quiet: results and errors only)."""

    def __init__(self, quiet=False, verbose=False, stream=None):
        self.quiet, self.verbose = quiet, verbose
        self.stream = stream or sys.stderr
        self.tty = self.stream.isatty()
        self.bold = ("\033[1m", "\033[0m") if self.tty else ("", "")
        self.lock = threading.Lock()
        self.line_open = False  # a progress line is on the screen, without its newline

    def _end_line(self):
        if self.line_open:
            self.stream.write("\n")
            self.line_open = False

    def say(self, message):
        if self.quiet:
            return
        with self.lock:
            self._end_line()
            self.stream.write(f"{self.bold[0]}orbed:{self.bold[1]} {message}\n")
            self.stream.flush()

    def error(self, message):
        with self.lock:
            self._end_line()
            self.stream.write(f"orbed: error: {message}\n")
            self.stream.flush()

    def echo(self, text):
        """A child's line, shown with --verbose."""
        with self.lock:
            self._end_line()
            self.stream.write(text if text.endswith("\n") else text + "\n")
            self.stream.flush()

    def progress(self, line, final=False):
        """On a terminal the line is rewritten in place (\\r); otherwise one line per call."""
        if self.quiet:
            return
        with self.lock:
            if self.tty and not self.verbose:
                self.stream.write("\r\033[K" + line + ("\n" if final else ""))
                self.line_open = not final
            else:
                self._end_line()
                self.stream.write(line + "\n")
            self.stream.flush()

    def results(self, text):
        """The results table: on stdout, once, whatever --quiet says."""
        with self.lock:
            self._end_line()
            self.stream.flush()
        sys.stdout.write(text if text.endswith("\n") or not text else text + "\n")
        sys.stdout.flush()


class Progress:
    """One long piece of work in n steps: WHAT k/n, elapsed, estimate (format_progress)."""

    def __init__(self, console, what, n):
        self.console, self.what, self.n, self.k = console, what, n, 0
        self.started = time.monotonic()
        self.detail = ""
        self.last = None  # the line shown last
        self.weights = None  # step name -> weight, when steps weigh differently (weighted_left)
        self.done_weight = 0.0

    def left_s(self):
        if not self.weights:
            return None
        left = max(0.0, sum(self.weights.values()) - self.done_weight)
        return weighted_left(self.elapsed(), self.done_weight, left)

    def elapsed(self):
        return time.monotonic() - self.started

    def show(self, detail=None, final=False):
        if detail is not None:
            self.detail = detail
        line = format_progress(self.what, self.k, self.n, self.elapsed(), self.left_s())
        line += f" ({self.detail})" if self.detail else ""
        if line != self.last or final:
            self.console.progress(line, final=final)
            self.last = line

    def step(self, detail=None):
        self.k = min(self.n, self.k + 1)
        self.show(detail)

    def done(self, detail=None):
        """The last line: on a terminal it ends the rewritten line; otherwise shown if new."""
        shown_all = self.last is not None and self.last.startswith(f"{self.what} {self.n}/{self.n},")
        self.k = self.n
        if self.console.tty:
            self.show(detail, final=True)
        elif not shown_all:
            self.show(detail)


def tail(path, lines=40):
    try:
        with open(path, errors="replace") as f:
            return "".join(f.readlines()[-lines:])
    except OSError:
        return ""


def run_logged(argv, log_path, console, env=None, on_line=None, cwd=None):
    """Runs argv with stdout and stderr into log_path (appended); each line is shown with --verbose
    and given to on_line (progress). Returns the exit code."""
    with open(log_path, "a") as log:
        child = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, env=env, cwd=cwd,
                                 text=True, errors="replace", stdin=subprocess.DEVNULL)
        for line in child.stdout:
            log.write(line)
            log.flush()
            if console.verbose:
                console.echo(line)
            if on_line:
                on_line(line)
        return child.wait()


def show_failure(console, log_path, lines=40):
    """The tail of a failing step's log, and where the whole of it is."""
    console.echo(f"--- the last lines of {log_path} ---\n{tail(log_path, lines)}--- end of {log_path} ---")
