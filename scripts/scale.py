#!/usr/bin/python3
"""orbed scale: the testbed as arms x headsets grow (docs/benchmarks.md, "Arms x headsets").

Each point of the grid runs orbed-load --arms A --headsets H (tests/load: A orbed-iiwa-sim --arm
a<i> in sim/models/scenes/four_arms_or.yaml, H orbed-hmd --headset h<j> looking at arm a<j mod A>,
each a different person, plus the logger and the monitor, at --factor times the nominal rates) in a
private network namespace of its own, for DURATION s after every process is ready, and reads its
JSON report: per process CPU (% of one core, from /proc between the early sample and the end) and
resident memory at the end; per stream wanted and achieved rate, drops counted by the publisher and
datagrams lost on the way; per camera the capture-to-receive latency (the receiver's stamp minus the
frame's sample stamp, one host's wall clock); the logger's drops and the kernel's socket drops.

Then it fits what each added arm and headset costs (least squares over the grid: CPU and memory =
base + a * arms + h * headsets + r * the messages all processes hear per second, since LCM's
multicast delivers every datagram to every process) and writes into OUT:
  scale.csv   one row per point;
  scale.json  the points and the fit;
  scale.png   CPU by kind of process against the machine's cores, and each point's camera latency
              (p50, p99) against the goal (p99 <= 15 ms);
and prints the table. A point "holds" when every stream reached its rate (achieved >= 98 % of
wanted), nothing was dropped or lost and no process died or restarted. Run by `scripts/orbed scale`;
needs python3-matplotlib.
"""
import argparse
import csv
import json
import os
import subprocess
import sys

LATENCY_GOAL_P99_MS = 15.0  # the goal: every camera's p99 at most 15 ms at 4 x 4
RATE_HELD = 0.98            # achieved / wanted for a stream to count as at its rate


def parse_grid(text):
    points = []
    for item in text.split(","):
        try:
            arms, headsets = (int(x) for x in item.strip().lower().split("x"))
        except ValueError:
            sys.exit(f"scale: grid point '{item}' is not AxH (e.g. 2x3)")
        points.append((arms, headsets))
    return points


def kind(process):
    if process.startswith("sim_"):
        return "arms (orbed-iiwa-sim)"
    if process.startswith("hmd_"):
        return "headsets (orbed-hmd)"
    return {"logger": "logger", "monitor": "monitor"}.get(process, "other")


def summarize(report):
    """The row of one point from orbed-load's JSON report."""
    processes = report["processes"]
    streams = report["streams"]
    cpu = {}
    for p in processes:
        cpu[kind(p["name"])] = cpu.get(kind(p["name"]), 0.0) + (p["cpu_percent"] or 0.0)
    cpu["watcher (orbed-load)"] = report["watcher_cpu_percent"] or 0.0
    lat = report["latencies"]
    slowest = min((s["achieved_hz"] / s["wanted_hz"] for s in streams), default=0.0)
    drops = sum(s["drops"] for s in streams)
    lost = sum(s["lost"] or 0 for s in streams)
    socket_drops = sum(max(p["socket_drops"], 0) for p in processes) + max(report["watcher_socket_drops"], 0)
    deaths = sum(1 for p in processes if not p["alive_at_end"] or p["respawns"] > 0)
    row = {
        "arms": report["arms"],
        "headsets": report["headsets"],
        "cpu_percent_testbed": sum((p["cpu_percent"] or 0.0) for p in processes),
        "cpu_percent_watcher": cpu["watcher (orbed-load)"],
        "rss_mb_testbed": sum(max(p["rss_end_kb"], 0) for p in processes) / 1024.0,
        "streams": len(streams),
        "slowest_rate_fraction": slowest,
        "drops": drops,
        "lost": lost,
        "socket_drops": socket_drops,
        "logger_drops": report["logger"]["drops"],
        "died_or_restarted": deaths,
        "camera_p50_ms": max((l["p50_ms"] for l in lat), default=float("nan")),
        "camera_p99_ms": max((l["p99_ms"] for l in lat), default=float("nan")),
        "camera_max_ms": max((l["max_ms"] for l in lat), default=float("nan")),
    }
    row["holds"] = (slowest >= RATE_HELD and drops == 0 and lost == 0 and socket_drops == 0
                    and row["logger_drops"] == 0 and deaths == 0)
    row["latency_goal"] = row["camera_p99_ms"] <= LATENCY_GOAL_P99_MS
    return row, cpu


# Messages per second on the bus per arm (IIWA_STATUS, ROBOT_STATE, COLLISION_STATUS at 200 Hz) and
# per headset (HMD_POSE, HMD_POSE_TRUTH 60, HMD_CAMERA 30, REFLECTIVE_VIEW 30, GAZE_RAY 10, AR_VIEW 5
# Hz), at the nominal rates; the logger and the monitor publish 1 Hz heartbeats only.
MSGS_PER_ARM_HZ = 600.0
MSGS_PER_HEADSET_HZ = 195.0


def heard_k(arms, headsets, factor):
    """Thousands of messages per second heard by all the testbed's processes together: LCM's UDP
    multicast delivers every datagram to every process (A + H + 2 of them), each of which reads it
    and drops what it does not subscribe to."""
    processes = arms + headsets + 2
    return processes * factor * (MSGS_PER_ARM_HZ * arms + MSGS_PER_HEADSET_HZ * headsets) / 1000.0


def fit(rows, key, factor):
    """Least squares key = base + a * arms + h * headsets + r * heard_k over the grid (None with
    fewer than 4 independent points), and the marginal cost of one more arm and one more headset at
    each point's size (the own work plus what every process pays to hear the new streams and the
    new process pays to hear all)."""
    import numpy
    x = numpy.array([[1.0, r["arms"], r["headsets"], heard_k(r["arms"], r["headsets"], factor)] for r in rows])
    y = numpy.array([r[key] for r in rows])
    if numpy.linalg.matrix_rank(x) < 4:
        return None
    (base, per_arm, per_headset, per_heard_k), *_ = numpy.linalg.lstsq(x, y, rcond=None)
    result = {"base": base, "per_arm": per_arm, "per_headset": per_headset, "per_k_msgs_heard": per_heard_k,
              "marginal": {}}
    for r in rows:
        a, h = r["arms"], r["headsets"]
        here = heard_k(a, h, factor)
        result["marginal"][f"{a}x{h}"] = {
            "arm": per_arm + per_heard_k * (heard_k(a + 1, h, factor) - here),
            "headset": per_headset + per_heard_k * (heard_k(a, h + 1, factor) - here)}
    return result


def plot(rows, cpus, cores, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    labels = [f"{r['arms']}x{r['headsets']}" for r in rows]
    kinds = ["arms (orbed-iiwa-sim)", "headsets (orbed-hmd)", "logger", "monitor", "watcher (orbed-load)"]
    fig, (ax_cpu, ax_lat) = plt.subplots(1, 2, figsize=(12, 4.5))
    bottom = [0.0] * len(rows)
    for k in kinds:
        values = [c.get(k, 0.0) for c in cpus]
        ax_cpu.bar(labels, values, bottom=bottom, label=k)
        bottom = [b + v for b, v in zip(bottom, values)]
    ax_cpu.axhline(100 * cores, color="black", linestyle="--", label=f"{cores} cores")
    ax_cpu.set_xlabel("arms x headsets")
    ax_cpu.set_ylabel("CPU [% of one core]")
    ax_cpu.set_title("CPU by kind of process")
    ax_cpu.legend(fontsize=8)
    ax_lat.plot(labels, [r["camera_p50_ms"] for r in rows], "o-", label="p50 (slowest camera)")
    ax_lat.plot(labels, [r["camera_p99_ms"] for r in rows], "s-", label="p99 (slowest camera)")
    ax_lat.axhline(LATENCY_GOAL_P99_MS, color="red", linestyle="--", label="goal: p99 <= 15 ms")
    ax_lat.set_xlabel("arms x headsets")
    ax_lat.set_ylabel("HMD_CAMERA capture -> receive [ms]")
    ax_lat.set_title("Camera latency")
    ax_lat.set_ylim(bottom=0)
    ax_lat.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--load", required=True, help="the orbed-load binary")
    parser.add_argument("--netns-exec", required=True, help="scripts/netns-exec")
    parser.add_argument("--out", required=True, help="output folder (created)")
    parser.add_argument("--grid", default="1x1,2x1,4x1,1x2,1x4,2x2,3x3,4x4,4x8",
                        help="points AxH, comma-separated (arms 1..4, headsets 1..8)")
    parser.add_argument("--duration-s", type=float, default=30, help="each point's run after ready [s]")
    parser.add_argument("--factor", type=float, default=1, help="times the nominal rates")
    parser.add_argument("--keep-logs", action="store_true", help="keep each point's .lcm log")
    args = parser.parse_args()
    points = parse_grid(args.grid)
    os.makedirs(args.out, exist_ok=True)
    cores = os.cpu_count() or 1
    rows, cpus = [], []
    for n, (arms, headsets) in enumerate(points, 1):
        point_dir = os.path.join(args.out, f"{arms}x{headsets}")
        os.makedirs(point_dir, exist_ok=True)
        report_path = os.path.join(point_dir, "report.json")
        print(f"scale: [{n}/{len(points)}] {arms} arm(s) x {headsets} headset(s), {args.duration_s:g} s ...",
              flush=True)
        with open(os.path.join(point_dir, "orbed-load.txt"), "w") as out:
            code = subprocess.call(
                [args.netns_exec, args.load, "--arms", str(arms), "--headsets", str(headsets),
                 "--factor", str(args.factor), "--duration-s", str(args.duration_s),
                 "--rss-early-s", str(min(10.0, args.duration_s / 3)), "--log-dir", point_dir,
                 "--json", report_path], stdout=out, stderr=subprocess.STDOUT)
        if not args.keep_logs:
            for name in os.listdir(point_dir):
                if name.endswith(".lcm"):
                    os.remove(os.path.join(point_dir, name))
        if not os.path.exists(report_path):
            sys.exit(f"scale: orbed-load failed at {arms}x{headsets} (exit code {code}); see {point_dir}/orbed-load.txt")
        with open(report_path) as f:
            row, cpu = summarize(json.load(f))
        rows.append(row)
        cpus.append(cpu)
        print(f"scale:   CPU {row['cpu_percent_testbed']:.0f} % of one core, {row['rss_mb_testbed']:.0f} MB, "
              f"camera p99 {row['camera_p99_ms']:.1f} ms, {'holds' if row['holds'] else 'DOES NOT HOLD'}",
              flush=True)

    fields = list(rows[0].keys())
    with open(os.path.join(args.out, "scale.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=fields)
        writer.writeheader()
        writer.writerows(rows)
    fits = {key: fit(rows, key, args.factor) for key in ("cpu_percent_testbed", "rss_mb_testbed")}
    with open(os.path.join(args.out, "scale.json"), "w") as f:
        json.dump({"factor": args.factor, "duration_s": args.duration_s, "cores": cores, "points": rows,
                   "fit": fits}, f, indent=2)
    plot(rows, cpus, cores, os.path.join(args.out, "scale.png"))

    print()
    print(f"| arms x headsets | streams | CPU [% of 1 core] | RSS [MB] | slowest stream [% of rate] | "
          f"drops / lost / socket | camera p50 / p99 [ms] | holds |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['arms']} x {r['headsets']} | {r['streams']} | {r['cpu_percent_testbed']:.0f} | "
              f"{r['rss_mb_testbed']:.0f} | {100 * r['slowest_rate_fraction']:.1f} | "
              f"{r['drops']} / {r['lost']} / {r['socket_drops']} | "
              f"{r['camera_p50_ms']:.1f} / {r['camera_p99_ms']:.1f} | {'yes' if r['holds'] else 'no'} |")
    largest = f"{rows[-1]['arms']}x{rows[-1]['headsets']}"
    for key, unit in (("cpu_percent_testbed", "% of one core"), ("rss_mb_testbed", "MB")):
        f_ = fits[key]
        if f_:
            at = f_["marginal"][largest]
            print(f"scale: {key} = {f_['base']:.1f} + {f_['per_arm']:.1f} per arm + {f_['per_headset']:.1f} "
                  f"per headset + {f_['per_k_msgs_heard']:.2f} per 1000 messages/s heard [{unit}]; one more arm "
                  f"at {largest}: +{at['arm']:.1f}, one more headset: +{at['headset']:.1f}")
    print(f"scale: {cores} cores; scale.csv, scale.json and scale.png in {args.out}")
    return 0 if all(r["holds"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
