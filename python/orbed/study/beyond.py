"""Numbers the paper did not report (tables.json "beyond"), from setup_docking.csv and, with
--registration-share runs, setup_truth_joints.csv (setup_joints.csv's columns, the same users'
headset modes run with the true registration).

  docking:    {mode: {"tip_mm": summarize, "axis_deg": summarize}} over the set-ups that recorded it
  collisions: {mode: {"setups", "contact", "collision_stops", "near_miss", "min_clearance_m"}}: a
              near miss is a set-up that touched nothing but came closer than NEAR_MISS_M
  registration_share: {mode: {"measured_deg", "truth_deg", "share": 1 - truth mean / measured mean}}
"""
from .describe import summarize
from .files import MODES

# The plan's own clearance for its targets (sim/trocar_plan.h min_clearance_m) [m].
NEAR_MISS_M = 0.05


def docking(df):
    out = {}
    for mode in MODES:
        rows = df[df["mode"] == mode]
        tip = rows["docking_tip_mm"].dropna()
        if tip.empty:
            continue
        out[mode] = {"tip_mm": summarize(tip), "axis_deg": summarize(rows["docking_axis_deg"].dropna())}
    return out


def collisions(df):
    out = {}
    for mode in MODES:
        rows = df[df["mode"] == mode]
        if rows.empty:
            continue
        contact = rows["contact"].astype(int) != 0
        clearance = rows["min_clearance_m"]
        near = (~contact) & clearance.notna() & (clearance < NEAR_MISS_M)
        c = {"setups": int(len(rows)), "contact": int(contact.sum()),
             "collision_stops": int(rows["collision_stops"].astype(int).sum()), "near_miss": int(near.sum())}
        if clearance.notna().any():
            c["min_clearance_m"] = summarize(clearance.dropna())
        out[mode] = c
    return out


def registration_share(joints, truth_joints):
    out = {}
    for mode in MODES:
        measured = joints.loc[joints["mode"] == mode, "error_deg"]
        truth = truth_joints.loc[truth_joints["mode"] == mode, "error_deg"]
        if measured.empty or truth.empty:
            continue
        m, t = summarize(measured), summarize(truth)
        out[mode] = {"measured_deg": m, "truth_deg": t, "share": 1 - t["mean"] / m["mean"] if m["mean"] > 0 else 0.0}
    return out


def beyond(docking_df, joints, truth_joints=None):
    out = {}
    if docking_df is not None:
        out["docking"] = docking(docking_df)
        out["near_miss_m"] = NEAR_MISS_M
        out["collisions"] = collisions(docking_df)
    if truth_joints is not None and joints is not None:
        out["registration_share"] = registration_share(joints, truth_joints)
    return out
