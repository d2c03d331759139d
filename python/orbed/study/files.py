"""A study folder's CSV files as pandas frames.

orbed-study-tables writes them (experiments/viraal/study_tables.h, experiments/setup/setup_tables.h);
the columns every reader may rely on are those of docs/studies.md, more columns may follow. Optional
columns read here when present:
  setup_joints.csv   start_id, target_id (strings), start_deg (the joint's angle at the set-up's start)
  setup_times.csv    start_id, target_id
  alignment_trials.csv  v_x_mm, v_y_mm, v_z_mm (per-axis error in a viewer frame, z the line of sight)
Each reader returns None when its file is absent. Users, modes and ids stay strings; target stays
an int (its index in the user's list of targets).
"""
import os

import pandas as pd

MODES = ("ar_reflective", "ar", "fixed")
# The pairs Table 3 compares, in the paper's order.
PAIRS = ("ar_reflective/ar", "ar_reflective/fixed", "ar/fixed")
STRINGS = {"user": str, "mode": str, "trial": str, "start_id": str, "target_id": str, "group": str,
           "landmarks": str}


def read(study_dir, name):
    path = os.path.join(study_dir, name)
    if not os.path.exists(path):
        return None
    return pd.read_csv(path, dtype=STRINGS, keep_default_na=True)


def setup_joints(study_dir, name="setup_joints.csv"):
    """One row per set-up and joint; adds `target_key`: target_id when the file has it, else the
    target index as a string (the per-target breakdown groups by it)."""
    df = read(study_dir, name)
    if df is None:
        return None
    return with_target_key(df)


def with_target_key(df):
    df = df.copy()
    if "target_id" in df.columns and df["target_id"].notna().all():
        df["target_key"] = df["target_id"].astype(str)
    else:
        df["target_key"] = df["target"].astype(int).astype(str)
    return df


def setup_times(study_dir):
    df = read(study_dir, "setup_times.csv")
    return None if df is None else with_target_key(df)


def pair_modes(pair):
    a, b = pair.split("/")
    return a, b
