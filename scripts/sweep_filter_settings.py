#!/usr/bin/env python3
"""Sweeps each filter setting tuned at run time across its declared range.

For every value, the filters that use the setting run on the pairs of `sift_hull_bench
evaluate-filters` (kept: mean over seeds 0 to 4 for the randomised filters) and on three pairs of
the demo scene (`sift_hull scene --views 16 --size 640x480`, views 2-3, 3-4 and 4-5, seed 0). Prints
a Markdown table: setting, value, filter, kept per pair, and the smallest recall (the share of a
pair's correct putatives kept) over the pairs where the default value keeps at least 80 %.

  scripts/sweep_filter_settings.py --bin DIR --data ../shared/data --scene DIR [--jobs 2]
"""

import argparse
import concurrent.futures
import json
import os
import subprocess
import sys

# setting: (the filters that use it, values from one end of its range to the other; a range open
# at 0 starts at the smallest value anyone would set, as in test_filter_ranges)
SWEEP = {
    "epipolar_max_distance_px": (["epipolar"], [0.1, 0.5, 2, 10, 50, 100]),
    "gsc_max_histogram_distance": (["gsc"], [0.1, 0.2, 0.5, 1, 1.5]),
    "ransac_max_epipolar_px": (["ransac"], [0.1, 0.5, 1, 5, 20, 100]),
    "magsac_max_epipolar_px": (["magsac", "guided", "vote_ransac"],
                               [0.1, 0.5, 1, 5, 20, 42, 100]),
    "gms_threshold_factor": (["gms"], [0.1, 1, 3, 6, 12]),
    "lsc_max_relative_error": (["lsc", "guided"], [0.2, 0.35, 0.7, 1, 1.5, 2]),
    "lsc_min_support": (["lsc", "guided"], [0, 0.1, 0.2, 0.25, 0.3]),
    "local_gsc_max_histogram_distance": (["local_gsc"], [0.2, 0.35, 0.7, 1, 1.5]),
    "guided_max_transfer_px": (["guided", "vote_ransac"], [0.1, 0.5, 3, 10, 30, 100]),
    "guided_min_support": (["guided"], [0, 0.1, 0.2, 0.25, 0.3]),
    "vote_ransac_max_angle_deg": (["vote_ransac"], [0.5, 5, 15, 30, 45, 60]),
    "vote_ransac_max_scale_ratio": (["vote_ransac"], [1.01, 1.1, 1.5, 2, 4, 16, 1000]),
}
# the defaults (a value of each sweep)
DEFAULTS = {"epipolar_max_distance_px": 2, "gsc_max_histogram_distance": 0.2,
            "ransac_max_epipolar_px": 1, "magsac_max_epipolar_px": 1, "gms_threshold_factor": 6,
            "lsc_max_relative_error": 0.35, "lsc_min_support": 0.25,
            "local_gsc_max_histogram_distance": 0.35, "guided_max_transfer_px": 3,
            "guided_min_support": 0.1, "vote_ransac_max_angle_deg": 30,
            "vote_ransac_max_scale_ratio": 2}
DEMO_PAIRS = [(2, 3), (3, 4), (4, 5)]


def flag(setting):
    return "--" + setting.replace("_", "-")


def run_json(command):
    out = subprocess.run(command, check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def evaluation_pairs(args, setting, value, filters):
    """{pair: {filter: (kept, recall)}} on evaluate-filters' pairs."""
    command = [os.path.join(args.bin, "sift_hull_bench"), "evaluate-filters", "--data", args.data,
               "--filters", ",".join(filters), flag(setting), str(value), "--json"]
    rows = {}
    for row in run_json(command)["pairs"]:
        name = "%s %s" % (row["pair"], row["ratio"]) if row["pair"] == "teddy" else row["pair"]
        rows[name] = {f: (run["kept"], run["recall"]) for f, run in row["filters"].items()}
    return rows


def demo_pairs(args, setting, value, filters):
    rows = {}
    for left, right in DEMO_PAIRS:
        image = lambda v: os.path.join(args.scene, "view_%04d.png" % v)
        command = [os.path.join(args.bin, "sift_hull"), "match", image(left), image(right),
                   "--gt-scene", args.scene, flag(setting), str(value), "--json"]
        for f in filters:
            command += ["--filter", f]
        result = run_json(command)["filters"]
        rows["demo %d-%d" % (left, right)] = {f: (result[f]["kept"], result[f]["recall"])
                                              for f in filters}
    return rows


def filters_of(args, setting):
    wanted = args.filters.split(",") if args.filters else []
    return [f for f in SWEEP[setting][0] if not wanted or f in wanted]


def measure(args, setting, value):
    filters = filters_of(args, setting)
    rows = evaluation_pairs(args, setting, value, filters)
    if args.scene:
        rows.update(demo_pairs(args, setting, value, filters))
    return setting, value, rows


def cell(kept):
    return ("%g" % round(kept, 1)) if kept is not None else "-"


def handled_well(results):
    """{(setting, filter): the pairs where the default value keeps >= 80 % of the correct}."""
    handled = {}
    for setting, value, rows in results:
        if value != DEFAULTS[setting]:
            continue
        for pair, runs in rows.items():
            for f, (_, recall) in runs.items():
                if recall is not None and recall >= 0.8:
                    handled.setdefault((setting, f), set()).add(pair)
    return handled


def table(results):
    pairs = []
    for _, _, rows in results:
        pairs += [p for p in rows if p not in pairs]
    handled = handled_well(results)
    lines = ["| setting | value | filter | " + " | ".join(pairs) + " | least recall |",
             "| --- " * (len(pairs) + 4) + "|"]
    for setting, value, rows in results:
        for f in [f for f in SWEEP[setting][0] if any(f in r for r in rows.values())]:
            runs = [rows.get(p, {}).get(f) for p in pairs]
            good = handled.get((setting, f), set())
            recalls = [r[1] for p, r in zip(pairs, runs)
                       if p in good and r is not None and r[1] is not None]
            least = "%.3f" % min(recalls) if recalls else "-"
            kept = [cell(r[0]) if r is not None else "-" for r in runs]
            lines.append("| %s | %g | %s | %s | %s |" % (setting, value, f, " | ".join(kept),
                                                          least))
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bin", required=True, help="directory of sift_hull and sift_hull_bench")
    parser.add_argument("--data", required=True, help="the real data sets' root")
    parser.add_argument("--scene", default="", help="the demo scene's directory (optional)")
    parser.add_argument("--settings", default="", help="comma-separated settings (default: all)")
    parser.add_argument("--filters", default="", help="comma-separated filters (default: all)")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--json", default="", help="also write the measurements here")
    args = parser.parse_args()
    settings = args.settings.split(",") if args.settings else list(SWEEP)
    jobs = [(s, v) for s in settings for v in SWEEP[s][1]]
    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        results = list(pool.map(lambda job: measure(args, *job), jobs))
    if args.json:
        with open(args.json, "w") as out:
            json.dump([{"setting": s, "value": v, "pairs": r} for s, v, r in results], out)
    print(table(results))
    return 0


if __name__ == "__main__":
    sys.exit(main())
