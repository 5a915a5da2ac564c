#!/usr/bin/env python3
"""Antialiased multi-fragment rendering (issue 26): error at equal bytes per pixel with 1 and S
samples, and what per-pixel coverage masks save over per-sample nodes at equal error.

    bench/msaa_table.py MFR [--scene SRC] [--extra "ARGS"] [--size N] [--samples S]
                        [--methods a,b,...] [--bpp 64,128,256] [--out DIR]

For one scene it runs `mfr compare` three times, each against its own exact answer:
  1 sample (the A-buffer of pixel centres), S samples with per-pixel nodes carrying coverage masks
  (--sample-storage pixel), S samples with nodes per sample (--sample-storage sample); the ground
truth of both S-sample runs is the per-sample A-buffer, box-filtered. Budgets are absolute, the
same bytes per pixel in every run. It also scores each 1-sample image against the S-sample truth
(the aliasing a 1-sample render keeps) with `mfr metrics`.

Prints a markdown table and writes msaa_table.csv into --out (default bench-results/msaa).
Default scene: procedural:hairball at 1024 x 1024, 4 samples; the Dish: --scene
../shared/scenes/khronos/IridescentDishWithOlives/glTF/IridescentDishWithOlives.gltf
--extra "--alpha 0.5 --zoom 1.6".
"""
import argparse
import csv
import json
import math
import os
import re
import shlex
import subprocess
import sys
import time


def compare(mfr, scene, extra, size, samples, storage, methods, budgets, out):
    cmd = [mfr, "compare", scene, "--width", str(size), "--height", str(size), "--samples",
           str(samples), "--sample-storage", storage, "--methods", ",".join(methods),
           "--budget", ",".join(str(b) for b in budgets), "--out", out, "-q"] + shlex.split(extra)
    start = time.time()
    subprocess.run(cmd, check=True)
    with open(os.path.join(out, "results.json")) as f:
        results = json.load(f)
    print(f"  {samples} sample(s), {storage}: {time.time() - start:.0f} s", file=sys.stderr)
    return results


def flip_against(mfr, image, truth):
    text = subprocess.run([mfr, "metrics", image, truth], check=True, capture_output=True,
                          text=True).stdout
    mse = float(re.search(r"MSE\s+linear\s+([0-9.eE+-]+)", text).group(1))
    flip = float(re.search(r"FLIP\s+mean\s+([0-9.eE+-]+)", text).group(1))
    return mse, flip


def runs(results):
    """{(method, budget_bytes): run} of a compare's results.json."""
    table = {}
    for budget in results["budgets"]:
        for run in budget["methods"]:
            table[(run["name"], budget["budget_bytes"])] = run
    return table


def bytes_for_error(points, error):
    """The bytes at which a method's (bytes, error) curve reaches `error`, interpolated in log-log
    between the budgets measured; None outside them."""
    points = sorted(p for p in points if p[1] is not None)
    for (b0, e0), (b1, e1) in zip(points, points[1:]):
        if (e0 - error) * (e1 - error) <= 0 and e0 != e1:
            if e0 <= 0 or e1 <= 0 or error <= 0:
                return b1 if e1 <= error else b0
            t = (math.log(error) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(b0) + t * (math.log(b1) - math.log(b0)))
    if points and points[0][1] <= error:
        return points[0][0]
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("mfr")
    ap.add_argument("--scene", default="procedural:hairball")
    ap.add_argument("--extra", default="")
    ap.add_argument("--size", type=int, default=1024)
    ap.add_argument("--samples", type=int, default=4)
    ap.add_argument("--methods", default="kplus-heap,kplus-dynamic,vkb,dkb,linked-list,wboit")
    ap.add_argument("--bpp", default="32,64,128,256")
    ap.add_argument("--out", default=os.path.join("bench-results", "msaa"))
    a = ap.parse_args()
    methods = a.methods.split(",")
    pixels = a.size * a.size
    budgets = [int(float(b) * pixels) for b in a.bpp.split(",")]
    os.makedirs(a.out, exist_ok=True)
    configs = [(1, "pixel"), (a.samples, "pixel"), (a.samples, "sample")]
    results = {}
    for samples, storage in configs:
        folder = os.path.join(a.out, f"s{samples}_{storage}")
        results[(samples, storage)] = runs(
            compare(a.mfr, a.scene, a.extra, a.size, samples, storage, methods, budgets, folder))
    truth_s = os.path.join(a.out, f"s{a.samples}_sample", "ground_truth.png")

    rows = []
    for method in methods:
        for budget in budgets:
            row = {"method": method, "bytes_per_pixel": budget / pixels}
            for samples, storage in configs:
                run = results[(samples, storage)].get((method, budget), {})
                key = f"s{samples}_{storage}"
                ok = "error" not in run or run.get("error") is None
                row[key + "_mse"] = run.get("mse_linear") if ok else None
                row[key + "_flip"] = run.get("flip_mean") if ok else None
                row[key + "_bytes"] = run.get("bytes_used") if ok else None
                row[key + "_lost_edges"] = run.get("lost_at_edges")
                row[key + "_lost_inside"] = run.get("lost_inside")
                row[key + "_storage"] = run.get("sample_storage")
                if samples == 1 and ok and run.get("image"):
                    image = os.path.join(a.out, "s1_pixel", run["image"])
                    row["s1_vs_truthS_mse"], row["s1_vs_truthS_flip"] = flip_against(
                        a.mfr, image, truth_s)
            rows.append(row)
    # memory at equal error: the bytes per-pixel masks need for per-sample storage's error
    for method in methods:
        mine = [r for r in rows if r["method"] == method]
        curve = [(r["bytes_per_pixel"], r[f"s{a.samples}_pixel_mse"]) for r in mine]
        for r in mine:
            target = r[f"s{a.samples}_sample_mse"]
            need = bytes_for_error(curve, target) if target is not None else None
            r["pixel_bpp_at_sample_error"] = need

    with open(os.path.join(a.out, "msaa_table.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)

    def fmt(v, spec=".2e"):
        return "-" if v is None else format(v, spec)

    s = a.samples
    print(f"{a.scene} {a.extra} at {a.size}x{a.size}: MSE (linear) against each run's own truth; "
          f"1 sample also against the {s}-sample truth")
    print(f"| method | B/px | 1 sample | 1 sample vs {s}-sample truth | {s} samples, per-pixel "
          f"masks | {s} samples, per-sample nodes | B/px masks need for per-sample's error |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        need = r["pixel_bpp_at_sample_error"]
        print(f"| {r['method']} | {r['bytes_per_pixel']:.0f} | {fmt(r['s1_pixel_mse'])} | "
              f"{fmt(r.get('s1_vs_truthS_mse'))} | {fmt(r[f's{s}_pixel_mse'])} "
              f"({r[f's{s}_pixel_storage']}) | {fmt(r[f's{s}_sample_mse'])} | "
              f"{fmt(need, '.0f')} |")


if __name__ == "__main__":
    main()
