#!/usr/bin/env bash
# report_test.sh ROOT WORKDIR: scripts/report.py on a study's files (tests/testdata/study: the
# tables.json and CSVs of a real `scripts/orbed study --registration-share`, seed 1), the page then
# opened in headless Chromium:
#   - every picture the page shows decodes in the browser (report.html sets data-images-loaded on
#     <body> once loaded: "4/4");
#   - Tables 1-4 and the reviewer's analysis (python/orbed/study, run first) are there, and Table 2's means per mode equal the means recomputed here from
#     setup_joints.csv with Python's statistics module (the page formats them from tables.json);
#   - the bands, the rank-flip line, the landmark check, the per-target breakdown and the provenance
#     footer are there, and every figure's PDF linked from the page is a PDF. The bands' input is
#     made here, quickly and without the C++ tools: 5 "studies" each drawing the study's users with
#     replacement (a fixture for the page, not simulated studies), and tests/testdata/bands/
#     rank_flip.csv (`orbed-user-study --studies 20 --csv` with the defaults, seed 1); the
#     provenance record is hand-made;
#   - a screenshot of the page (WORKDIR/report.png) is a real picture.
# Needs Debian's chromium and python3-matplotlib (`scripts/orbed setup` installs them).
set -euo pipefail
root=$1 work=$2
rm -rf "$work"
mkdir -p "$work/study"
cp "$root"/tests/testdata/study/* "$work/study/"
# The analysis first, as scripts/orbed study runs it (python/orbed/study rewrites tables.json).
PYTHONPATH="$root/python" /usr/bin/python3 -m orbed.study "$work/study" >/dev/null
mkdir -p "$work/study/bands"
cp "$root/tests/testdata/bands/rank_flip.csv" "$work/study/bands/"
/usr/bin/python3 - "$work/study" <<'PY'
import csv, json, random, sys
study = sys.argv[1]
for name in ("alignment_trials.csv", "setup_joints.csv", "setup_times.csv"):
    rows = list(csv.DictReader(open(study + "/" + name)))
    users = sorted({r["user"] for r in rows})
    with open(study + "/bands/" + name, "w", newline="") as f:
        w = csv.DictWriter(f, ["study"] + list(rows[0]))
        w.writeheader()
        for m in range(5):
            for k, user in enumerate(random.Random(m).choices(users, k=len(users))):
                w.writerows({"study": m, **r, "user": "u%d" % (k + 1)} for r in rows if r["user"] == user)
tables = json.load(open(study + "/tables.json"))
json.dump({"paper": tables["paper"]}, open(study + "/bands/tables.json", "w"))
json.dump({"format": "orbed.provenance/1", "run": "study-test", "kind": "study", "orbed_version": "0",
           "git": {"commit": "c0ffee", "dirty": False}, "command_line": ["scripts/orbed", "study", "--bands", "5"],
           "started_utc": "2027-01-01T00:00:00Z", "ended_utc": None, "host": "testhost", "settings": {},
           "config_files": [], "outputs": []}, open(study + "/provenance.json", "w"))
PY
PYTHONPATH="$root/python" /usr/bin/python3 -m orbed.study.bands "$work/study/bands" >/dev/null
/usr/bin/python3 "$root/scripts/report.py" "$work/study" >/dev/null
for f in joint_errors total_errors joint_rank power; do
  for ext in png pdf; do
    [[ -s "$work/study/figures/$f.$ext" ]] || { echo "report_test: no figures/$f.$ext"; exit 1; }
  done
done

chrome() {
  chromium --headless --no-sandbox --disable-gpu --disable-dev-shm-usage --hide-scrollbars \
    --user-data-dir="$work/profile" --virtual-time-budget=10000 "$@" 2>"$work/chromium.err"
}
page="file://$work/study/report.html"
chrome --dump-dom "$page" >"$work/dom.html"
chrome --window-size=1200,2400 --screenshot="$work/report.png" "$page" >/dev/null

/usr/bin/python3 - "$work" <<'PY'
import csv, json, re, statistics, struct, sys
work = sys.argv[1]
dom = open(work + "/dom.html").read()
m = re.search(r'data-images-loaded="(\d+)/(\d+)"', dom)
assert m, "the page did not report its pictures (no data-images-loaded on <body>)"
assert m.group(1) == m.group(2) == "5", "pictures decoded in the browser: %s/%s" % m.groups()
for heading in ("Table 1", "Table 2", "Table 3", "Table 4", "The set-up half as a reviewer reads it",
                "Mixed-effects model", "Holm-corrected", "Per target", "Landmark check",
                "Predictive bands: the paper's figures against 5 simulated studies", "Rank flip: in ",
                "Made by orbed 0 at commit c0ffee, run study-test on host testhost"):
    assert heading in dom, heading + " is missing"
bands = json.load(open(work + "/study/bands/bands.json"))
count = "%d of %d paper figures inside" % (bands["inside"], bands["counted"])
assert count in dom, count + " is missing"
assert dom.count("<tr><th>table") == len(bands["figures"]), "not one bands row per figure"
pdfs = re.findall(r'href="([^"]+\.pdf)"', dom)
assert len(set(pdfs)) == 5, "PDFs linked: %s" % sorted(set(pdfs))
for pdf in set(pdfs):
    assert open(work + "/study/" + pdf, "rb").read(5) == b"%PDF-", pdf + " is no PDF"
table2 = dom[dom.index("Table 2"):dom.index("Table 3")]
rows = list(csv.DictReader(open(work + "/study/setup_joints.csv")))
labels = {"ar_reflective": "AR + reflective display", "ar": "AR", "fixed": "fixed display"}
for mode, label in labels.items():
    mean = statistics.mean(float(r["error_deg"]) for r in rows if r["mode"] == mode)
    row = re.search(r"<tr><th>%s</th><td>([^<]*)</td>" % re.escape(label), table2)
    assert row, "no Table 2 row for " + label
    assert row.group(1) == "%.1f" % mean, "%s: page %s, CSV mean %.1f" % (label, row.group(1), mean)
png = open(work + "/report.png", "rb").read()
assert png[:8] == b"\x89PNG\r\n\x1a\n", "the screenshot is no PNG"
width, height = struct.unpack(">II", png[16:24])
assert (width, height) == (1200, 2400), "screenshot %dx%d" % (width, height)
assert len(png) > 50_000, "the screenshot is nearly empty (%d bytes)" % len(png)
print("report_test: 5/5 pictures decoded, Tables 1-4, the bands (%s), the rank flip and the footer present, "
      "5 PDFs linked, Table 2 means equal the CSV's, screenshot %dx%d (%d bytes)" % (count, width, height, len(png)))
PY
