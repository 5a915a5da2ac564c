#!/usr/bin/env python3
"""Markdown tables from the mfr compare folders of scripts/evaluate-dkb.sh.

usage: eval_tables.py OUT_DIR  (reads OUT_DIR/*/results.json, prints markdown on stdout)
"""
import glob
import json
import math
import os
import sys
from collections import defaultdict

METHODS = ["fkb", "kplus-dynamic", "vkb", "vkb-fill", "dkb", "dkb-fill", "optimal"]


def fmt(v, kind):
    if v is None:
        return "n/a"
    if kind == "mse":
        return "%.2e" % v
    return "%.4f" % v


def geomean(values):
    values = [v for v in values if v is not None and v > 0]
    if not values:
        return None
    return math.exp(sum(math.log(v) for v in values) / len(values))


def main(out):
    # runs[(compositing, budget)][case][method] = run
    runs = defaultdict(lambda: defaultdict(dict))
    times = defaultdict(list)
    coverage = {}
    for path in sorted(glob.glob(os.path.join(out, "*", "results.json"))):
        case = os.path.basename(os.path.dirname(path))
        r = json.load(open(path))
        comp = r["compositing"]
        case = case.rsplit("_", 1)[0]  # drop the compositing suffix
        gt = r["ground_truth"]
        coverage[case] = (gt.get("fragments_generated"), r["width"] * r["height"])
        for b in r["budgets"]:
            for run in b["methods"]:
                runs[(comp, b["budget_label"])][case][run["name"]] = run
                if run["name"] in ("dkb", "dkb-fill") and "time_ms" in run:
                    t = run["time_ms"]
                    times["features"].append(t.get("features", 0.0))
                    times["inference"].append(t.get("inference", 0.0))
                    times["count"].append(t.get("count", 0.0))
    print("# Deep k-buffer evaluation (%s)\n" % out)
    for (comp, budget), cases in sorted(runs.items()):
        for metric, key in (("MSE (linear RGB)", "mse_linear"), ("mean FLIP", "flip_mean")):
            print("\n## %s compositing, M = %s: %s\n" % (comp, budget, metric))
            print("| scene / view | " + " | ".join(METHODS) + " | dkb / optimal |")
            print("|---" * (len(METHODS) + 2) + "|")
            per_method = defaultdict(list)
            ratios = []
            for case in sorted(cases):
                row = []
                for m in METHODS:
                    run = cases[case].get(m)
                    v = None if run is None or "error" in run else run.get(key)
                    per_method[m].append(v)
                    row.append(fmt(v, "mse" if key == "mse_linear" else "flip"))
                d = cases[case].get("dkb", {}).get(key)
                o = cases[case].get("optimal", {}).get(key)
                ratio = d / o if d is not None and o else None
                if ratio is not None:
                    ratios.append(ratio)
                print("| %s | %s | %s |" % (case, " | ".join(row),
                                           "n/a" if ratio is None else "%.2f" % ratio))
            means = [geomean(per_method[m]) for m in METHODS]
            g = geomean(ratios)
            print("| **geometric mean** | %s | %s |" % (
                " | ".join(fmt(v, "mse" if key == "mse_linear" else "flip") for v in means),
                "n/a" if g is None else "%.2f" % g))
            # how often the paper's ordering holds
            def wins(a, b):
                pairs = [(x, y) for x, y in zip(per_method[a], per_method[b])
                         if x is not None and y is not None]
                return sum(1 for x, y in pairs if x < y), sum(1 for x, y in pairs if x == y), len(pairs)
            for a, b in (("dkb", "vkb"), ("vkb", "fkb"), ("dkb-fill", "vkb-fill"), ("dkb", "fkb")):
                w, t, n = wins(a, b)
                print("\n%s < %s in %d of %d cases (%d ties)" % (a, b, w, n, t), end="")
            print()
    if times["features"]:
        n = len(times["features"])
        print("\n## dkb pass times at 1024x1024 (mean over %d runs, ms)\n" % n)
        for k in ("count", "features", "inference"):
            print("- %s: %.1f" % (k, sum(times[k]) / n))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "eval-results")
