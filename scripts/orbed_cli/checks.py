"""Argument types for argparse: each returns the value or raises ArgumentTypeError with one line
that says what was expected and what was given. Syntax only: nothing here looks at the disk, so
that a command line can be parsed anywhere (tests/cli/test_readme.py parses README's)."""
import argparse
import math
import re


def whole(low, high):
    """A whole number in [low, high] (decimal digits only)."""
    def parse(text):
        if not re.fullmatch(r"[0-9]{1,9}", text) or not low <= int(text) <= high:
            raise argparse.ArgumentTypeError(f"must be a whole number {low}..{high}, not '{text}'")
        return int(text)
    parse.__name__ = "whole number"
    return parse


def positive(text):
    """A finite number > 0."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value) or value <= 0:
        raise argparse.ArgumentTypeError(f"must be a positive number, not '{text}'")
    return text  # passed on as written


def non_negative(text):
    """A finite number >= 0."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value) or value < 0:
        raise argparse.ArgumentTypeError(f"must be a number >= 0, not '{text}'")
    return text  # passed on as written


def key_value(text):
    """NAME=VALUE with a non-empty NAME."""
    name, sep, _ = text.partition("=")
    if not sep or not name:
        raise argparse.ArgumentTypeError(f"expected NAME=VALUE, not '{text}'")
    return text


def run_id(text):
    if not re.fullmatch(r"[A-Za-z0-9._-]{1,64}", text):
        raise argparse.ArgumentTypeError(f"must be 1-64 letters, digits, '.', '_' or '-', not '{text}'")
    return text


def numbers(text):
    """A comma-separated list of finite numbers (A,B,...), the executables' one list syntax."""
    try:
        finite = all(math.isfinite(float(x)) for x in text.split(","))
    except ValueError:
        finite = False
    if not finite:
        raise argparse.ArgumentTypeError(f"expected finite numbers separated by commas, not '{text}'")
    return text


def grid(text):
    """AxH[,AxH...]: arms x headsets points."""
    if not re.fullmatch(r"[1-9][0-9]*x[1-9][0-9]*(,[1-9][0-9]*x[1-9][0-9]*)*", text):
        raise argparse.ArgumentTypeError(f"expected AxH,... (e.g. 1x1,2x2), not '{text}'")
    return text


def config_file(text):
    return ("--config", text)


def set_value(text):
    return ("--set", key_value(text))


def add_settings(parser):
    """SETTINGS: --config FILE and --set KEY=VALUE, repeatable, in the order given."""
    parser.add_argument("--config", action="append", dest="settings", type=config_file,
                        metavar="FILE", help="a YAML file of sections of orbed's configuration (repeatable)")
    parser.add_argument("--set", action="append", dest="settings", metavar="KEY=VALUE",
                        type=set_value,
                        help="one dotted key, e.g. user.direct_view.depth_bias_fraction_std=0.03 (repeatable)")
    parser.set_defaults(settings=[])
