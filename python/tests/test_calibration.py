"""The calibration set (experiments/calibration.yaml) against the files it names: each fitted value
equals the one shipped, and it lists exactly the parameters docs/parameters.md calls fitted."""
import os
import re

import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def load(relative):
    with open(os.path.join(ROOT, relative)) as f:
        return yaml.safe_load(f)


def lookup(tree, dotted):
    for part in dotted.split("."):
        tree = tree[part]
    return tree


def calibration():
    return load("experiments/calibration.yaml")["parameters"]


def test_each_fitted_value_is_the_shipped_one():
    for p in calibration():
        assert lookup(load(p["file"]), p["key"]) == p["value"], p["key"]


def test_lists_exactly_what_the_parameters_page_calls_fitted():
    with open(os.path.join(ROOT, "docs", "parameters.md")) as f:
        documented = set(re.findall(r"^\| `([^`]+)` \|[^|]*\|[^|]*\| fitted \|", f.read(), re.M))
    assert documented, "docs/parameters.md lists no fitted parameter: the pattern is stale"
    assert {p["key"] for p in calibration()} == documented


def test_every_parameter_names_figures_of_the_bands():
    figure = re.compile(r"^table1\.(ar|ar_reflective)\.norm_(mean|std)$|"
                        r"^table4\.(ar|ar_reflective|fixed)\.(execution_s|alignment_s)\.(mean|median|min|max|std)$")
    for p in calibration():
        assert p["fitted_to"] and all(figure.match(f) for f in p["fitted_to"]), p["key"]
        assert p["how"].strip(), p["key"]
