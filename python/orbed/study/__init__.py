"""The study's analysis: Tables 1-4, the reviewer's analysis of the set-up half and the power
analysis, from the CSV files orbed-study-tables writes (their columns: docs/studies.md).

One module per concern:
  files         reads a study folder's CSVs into pandas frames (optional columns, optional files)
  describe      the summary statistics every table uses (mean, median, min, max, sample std)
  tables        Tables 1-4 as the paper computes them (Table 3: the paper's reading, pooled MWU)
  beyond        numbers the paper did not report: docking, collisions, the registration's share
  setup_stats   the reviewer's analysis: the set-up as the unit, paired tests, Holm, mixed model,
                effect sizes, per target, half-turn rates
  power         the power analysis (bootstrap over users) of the paired and the pooled test
  analysis      all of it into tables.json, and the terminal summary
Run `python3 -m orbed.study STUDY_DIR` (with python/ on sys.path) to rewrite STUDY_DIR/tables.json.
"""
