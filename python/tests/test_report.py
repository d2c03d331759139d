"""scripts/report.py's sections from hand-made inputs: the provenance footer, the bands and the rank
flip, the landmark check, Table 1's SE(3) row, the figures (PDF + 300-dpi PNG) and the log axis."""
import importlib.util
import json
import math
import os
import re
import struct

import pytest

from conftest import ROOT

spec = importlib.util.spec_from_file_location("report", os.path.join(ROOT, "scripts", "report.py"))
report = importlib.util.module_from_spec(spec)
spec.loader.exec_module(report)


def write_json(path, value):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        json.dump(value, f)


PROVENANCE = {
    "format": "orbed.provenance/1", "run": "study-20270101T000000Z-ab12", "kind": "study", "orbed_version": "0.9.0",
    "git": {"commit": "0123456789abcdef0123456789abcdef01234567", "dirty": True, "changed": ["a.cc"]},
    "command_line": ["scripts/orbed", "study", "--bands", "5", "--set", "x=<y>"],
    "started_utc": "2027-01-01T00:00:00.000000Z", "ended_utc": "2027-01-01T00:01:30.000000Z", "exit_code": 0,
    "host": "orhost", "settings": {"seed": "1", "bands": "5"}, "config_files": [], "outputs": []}


def test_provenance_footer_names_commit_command_host_and_times(tmp_path):
    write_json(str(tmp_path / "provenance.json"), PROVENANCE)
    footer = report.provenance_footer(str(tmp_path))
    assert "at commit 0123456789abcdef0123456789abcdef01234567 (uncommitted changes)" in footer
    assert "run study-20270101T000000Z-ab12 on host orhost" in footer
    assert "started 2027-01-01T00:00:00.000000Z, finished 2027-01-01T00:01:30.000000Z with exit code 0" in footer
    # The command line as typed, HTML-escaped; the settings sorted by name.
    assert "<code>scripts/orbed study --bands 5 --set x=&lt;y&gt;</code>" in footer
    assert "Settings: bands=5, seed=1." in footer
    assert footer.startswith("<footer") and footer.endswith("</footer>")


def test_provenance_footer_of_an_unfinished_run_and_of_a_folder_without_one(tmp_path):
    record = dict(PROVENANCE, ended_utc=None, exit_code=None, git={"commit": "feed", "dirty": False})
    write_json(str(tmp_path / "a" / "provenance.json"), record)
    footer = report.provenance_footer(str(tmp_path / "a"))
    assert "at commit feed, run" in footer and "not finished when the report was made" in footer
    assert "No provenance.json" in report.provenance_footer(str(tmp_path))


def bands_folder(tmp_path):
    """A study folder with bands/bands.json (three figures: one inside, one outside, one calibrated)
    and bands/rank_flip.csv (four studies, one of them a flip)."""
    records = [
        {"figure": "table2.ar.mean", "paper": 26.8, "lo": 20.0, "median": 30.0, "hi": 40.0, "studies": 4,
         "inside": True, "calibrated": False},
        {"figure": "table3.ar/fixed.total", "paper": 2e-18, "lo": 1e-9, "median": 1e-6, "hi": 1e-3, "studies": 4,
         "inside": False, "calibrated": False},
        {"figure": "table4.ar.execution_s.mean", "paper": 91.0, "lo": 60.0, "median": 80.0, "hi": 100.0,
         "studies": 4, "inside": True, "calibrated": True}]
    write_json(str(tmp_path / "bands" / "bands.json"),
               {"studies": 4, "level": 0.95, "inside": 1, "counted": 2, "calibrated": [records[2]["figure"]],
                "figures": records})
    # Study 2 flips: measured ar_reflective < ar but truth ar_reflective > ar.
    rows = ["study,first_user_seed,mode,users,trials,measured_w_mm,measured_s_mm,true_translation_mm,"
            "true_misalignment_mm"]
    for study, (mr, ma, tr, ta) in enumerate([(10, 20, 11, 21), (12, 18, 13, 19), (10, 20, 30, 21), (25, 20, 24, 21)]):
        rows.append("%d,%d,ar_reflective,4,40,%d,%d,%d,%d" % (study, 1 + 4 * study, mr, mr, tr, tr))
        rows.append("%d,%d,ar,4,40,%d,%d,%d,%d" % (study, 1 + 4 * study, ma, ma, ta, ta))
    with open(str(tmp_path / "bands" / "rank_flip.csv"), "w") as f:
        f.write("\n".join(rows) + "\n")
    return str(tmp_path)


def test_bands_section_counts_and_marks_each_figure(tmp_path):
    page = "\n".join(report.bands_section(bands_folder(tmp_path)))
    assert "<b>1 of 2 paper figures inside</b>" in page and "against 4 simulated studies" in page
    rows = dict(re.findall(r"<tr><th>([^<]+)</th>(.*?)</tr>", page))
    assert "<td>inside</td>" in rows["table2.ar.mean"] and "<td>[20.0, 40.0]</td>" in rows["table2.ar.mean"]
    assert "<b>outside</b>" in rows["table3.ar/fixed.total"] and "<td class=paper>2e-18</td>" in rows[
        "table3.ar/fixed.total"]
    assert "calibrated (inside; not counted)" in rows["table4.ar.execution_s.mean"]
    # The figure: the PNG shown, the PDF linked.
    assert "<img src='bands/figures/bands.png'>" in page and "href='bands/figures/bands.pdf'" in page


def test_rank_flip_line_gives_the_flips_and_their_wilson_interval(tmp_path):
    line = report.rank_flip_line(os.path.join(bands_folder(tmp_path), "bands"))
    # Wilson score interval of 1 of 4 by its closed form (z the normal's 97.5th percentile).
    k, n, z = 1, 4, 1.959963984540054
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z / (1 + z * z / n) * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    assert "in 1 of 4 simulated studies (25.0 %%, 95 %% Wilson interval %.1f-%.1f %%)" % (
        100 * (centre - half), 100 * (centre + half)) in line
    assert report.rank_flip_line(str(tmp_path)) is None


def test_landmark_check_from_the_mean_and_the_rows(tmp_path):
    with open(str(tmp_path / "landmark_validation.csv"), "w") as f:
        f.write("repeat,separation_mm,measured_mm,error_mm\n1,50,53,3\n2,100,96,4\n3,50,52,2\n")
    text = report.landmark_check({"landmark_validation_mm": 3.0, "paper": {"landmark_validation_mm": 3.6}},
                                 str(tmp_path))
    assert "(3 measurements of pairs 50, 100 mm apart): mean error 3.0 mm (paper 3.6 mm" in text
    assert report.landmark_check({}, str(tmp_path)) == ""


def test_table1_shows_the_se3_row_of_groups_of_three():
    tables = {"table1": {"ar_reflective": {"norm": [15.0, 9.0]},
                         "se3_n3": {"ar_reflective": {"norm": [12.25, 2.5], "groups": 12}}},
              "paper": {"table1": {"ar_reflective": {"norm": [16.5, 11.0]}, "se3_mean": {"ar_reflective": {
                  "norm": [11.3, 1.01]}}}}}
    page = "\n".join(report.table1_section(tables))
    row = re.search(r"<tr><th>AR \+ reflective display: SE\(3\) means of N = 3 trials \(12 groups;[^<]*</th>"
                    r"<td>([^<]*)</td><td>([^<]*)</td><td class=paper>([^<]*)</td>", page)
    assert row and row.groups() == ("12.2", "2.5", "11.3 +/- 1.01")
    assert report.table1_section({}) == []


def png_chunks(data):
    pos, out = 8, {}
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        out[kind] = data[pos + 8:pos + 8 + length]
        pos += 12 + length
    return out


def test_save_writes_a_vector_pdf_and_a_300_dpi_png(tmp_path):
    fig, ax = report.plt.subplots(figsize=(2, 1))
    ax.plot([0, 1], [0, 1])
    report.save(fig, str(tmp_path), "f")
    with open(str(tmp_path / "figures" / "f.pdf"), "rb") as f:
        assert f.read(5) == b"%PDF-"
    with open(str(tmp_path / "figures" / "f.png"), "rb") as f:
        chunks = png_chunks(f.read())
    width, height = struct.unpack(">II", chunks[b"IHDR"][:8])
    assert (width, height) == (600, 300)  # 2 x 1 inches at 300 dpi
    # pHYs: pixels per metre, 300 / 0.0254 = 11811.02 -> 11811, unit 1 (metre).
    assert struct.unpack(">IIB", chunks[b"pHYs"]) == (11811, 11811, 1)
    assert report.figure_html("figures/f", "cap") == (
        "<figure><a href='figures/f.pdf'><img src='figures/f.png'></a><figcaption>cap (<a href='figures/f.pdf'>"
        "PDF</a>)</figcaption></figure>")


def test_log_degree_axis_ticks_the_decades_written_out():
    fig, ax = report.plt.subplots()
    report.log_degree_axis(ax, 0.1, 100)
    assert list(ax.get_yticks()) == [0.1, 1, 10, 100]
    assert [t.get_text() for t in ax.get_yticklabels()] == ["0.1", "1", "10", "100"]
    report.plt.close(fig)


@pytest.mark.parametrize("lo, hi, most, ticks", [
    (0.01, 250, 8, [0.01, 0.1, 1, 10, 100, 1000]),
    (2e-18, 0.9, 8, [1e-18, 1e-15, 1e-12, 1e-9, 1e-6, 1e-3, 1]),
])
def test_bands_decade_ticks(lo, hi, most, ticks):
    from orbed.study import bands
    assert bands.decade_ticks(lo, hi, most) == pytest.approx(ticks, rel=1e-12)
    assert [bands.tick_label(t) for t in ticks][:2] == (["0.01", "0.1"] if lo == 0.01 else ["1e-18", "1e-15"])


def test_sensitivity_section_lists_each_setting_beside_the_shipped_one(tmp_path):
    assert report.sensitivity_section(str(tmp_path)) == []  # no --sensitivity: no section
    (tmp_path / "sensitivity").mkdir()
    (tmp_path / "sensitivity" / "sensitivity.csv").write_text(
        "setting,output,value,baseline,change\n"
        "baseline,ar.mean_error_deg,80,80,0\n"
        "baseline,ar.half_turn_rate,0.44,0.44,0\n"
        "assistant.acting.choice=best,ar.mean_error_deg,104.25,80,24.25\n"
        "assistant.acting.choice=best,ar.half_turn_rate,0.5,0.44,0.06\n")
    page = "\n".join(report.sensitivity_section(str(tmp_path)))
    rows = dict(re.findall(r"<tr><th>([^<]+)</th>(.*?)</tr>", page))
    assert rows["baseline"] == "<td>80.0</td><td>0.44</td>"
    assert rows["assistant.acting.choice=best"] == "<td>104.2</td><td>0.50</td>"
    assert "<th>AR mean error [deg]</th><th>AR half-turn rate</th>" in page
    assert "<img src='sensitivity/figures/sensitivity.png'>" in page
