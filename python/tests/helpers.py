"""Small study folders written by the tests, in the CSV columns orbed-study-tables writes."""
import os

import pandas as pd

from orbed.study import files

JOINT_COLUMNS = ["user", "mode", "order", "target", "joint", "twisting", "target_deg", "reached_deg", "error_deg"]
TARGET_DEG = [10, 20, 0, -60, 0, 40, 0]


def joints_frame(setups):
    """setups: (user, mode, target, [7 errors]) -> a setup_joints frame (reached = target + error)."""
    rows = []
    for user, mode, target, errors in setups:
        for j, e in enumerate(errors):
            rows.append([user, mode, 1, target, j + 1, (j + 1) % 2, TARGET_DEG[j], TARGET_DEG[j] + e, abs(e)])
    return files.with_target_key(pd.DataFrame(rows, columns=JOINT_COLUMNS))


def write_csv(folder, name, frame):
    os.makedirs(folder, exist_ok=True)
    frame.to_csv(os.path.join(folder, name), index=False)
