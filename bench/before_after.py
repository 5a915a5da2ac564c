#!/usr/bin/env python3
"""Before/after figures of the deep k-buffer and the optimal oracle (issue 12), in one run.

    bench/before_after.py BEFORE_BUILD AFTER_BUILD [--reps N] [--out DIR]

Each round runs both builds' `mfr render` back to back (interleaved, so the slow periods of a
shared machine fall on both alike) and the medians are reported:
  - the Dish (IridescentDishWithOlives, ../shared/scenes) at 1024 x 1024, --alpha 0.5 --zoom 1.6,
    40 MB: a kplus-dynamic frame, and a dkb frame's features and inference passes (wall ms, from
    --stats-json);
  - procedural:hairball at 1024 x 1024, optimal at 120 MB: wall seconds and peak resident memory
    (/usr/bin/time -v), the oracle pass, and the oracle's error and bound (the same allocation
    gives the same figures).
Writes before_after.csv into --out (default bench-results).
"""
import argparse
import csv
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
DISH = os.path.join(HERE, "..", "..", "shared", "scenes", "khronos", "IridescentDishWithOlives",
                    "glTF", "IridescentDishWithOlives.gltf")


def render(cli, args, tmp):
    stats = os.path.join(tmp, "stats.json")
    cmd = ["/usr/bin/time", "-v", cli, "render"] + args + ["--out", os.path.join(tmp, "o.png"),
                                                           "--stats-json", stats]
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"before_after: {' '.join(cmd)} failed:\n{run.stderr}")
    rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", run.stderr).group(1))
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): ([\d:.]+)", run.stderr)
    parts = [float(x) for x in wall.group(1).split(":")]
    seconds = sum(p * 60 ** i for i, p in enumerate(reversed(parts)))
    with open(stats) as f:
        return json.load(f), seconds, rss / 1024.0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--out", default="bench-results")
    ap.add_argument("--skip-oracle", action="store_true")
    a = ap.parse_args()
    view = ["--width", "1024", "--height", "1024", "--alpha", "0.5", "--zoom", "1.6", "--budget",
            "40MB"]
    cases = []
    if os.path.exists(DISH):
        cases += [("dish kplus-dynamic", [DISH, "--method", "kplus-dynamic"] + view),
                  ("dish dkb", [DISH, "--method", "dkb"] + view)]
    else:
        print(f"skipping the Dish: {DISH} not found")
    if not a.skip_oracle:
        cases.append(("hairball optimal", ["procedural:hairball", "--method", "optimal", "--width",
                                           "1024", "--height", "1024", "--budget", "120MB"]))
    samples = {}
    with tempfile.TemporaryDirectory() as tmp:
        for rep in range(a.reps):
            print(f"  round {rep + 1}/{a.reps}", file=sys.stderr, flush=True)
            for name, args in cases:
                for side, build in (("before", a.before), ("after", a.after)):
                    stats, seconds, rss = render(os.path.join(build, "mfr"), args, tmp)
                    s = samples.setdefault((name, side), {})
                    for k, v in stats["time_ms"].items():
                        s.setdefault(k, []).append(v)
                    s.setdefault("total", []).append(stats["total_ms"])
                    s.setdefault("wall_s", []).append(seconds)
                    s.setdefault("peak_rss_mib", []).append(rss)
                    oracle = stats.get("oracle_error")
                    if oracle is not None:
                        s.setdefault("oracle_error", []).append(oracle)
                        s.setdefault("oracle_lower_bound", []).append(stats["oracle_lower_bound"])
    os.makedirs(a.out, exist_ok=True)
    path = os.path.join(a.out, "before_after.csv")
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["case", "side", "figure", "median", "samples"])
        for (name, side), s in samples.items():
            for k, v in sorted(s.items()):
                w.writerow([name, side, k, statistics.median(v), " ".join(f"{x:g}" for x in v)])
    for name, _ in cases:
        b, f = samples[(name, "before")], samples[(name, "after")]
        print(f"\n{name}:")
        print(f"  {'figure':<22} {'before':>14} {'after':>14}")
        for k in sorted(set(b) | set(f)):
            mb = f"{statistics.median(b[k]):.6g}" if k in b else "-"
            ma = f"{statistics.median(f[k]):.6g}" if k in f else "-"
            print(f"  {k:<22} {mb:>14} {ma:>14}")
    print(f"\nCSV: {path}")


if __name__ == "__main__":
    main()
