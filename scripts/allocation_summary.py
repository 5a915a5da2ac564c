#!/usr/bin/env python3
"""The summary of scripts/evaluate-allocation.sh: one table over every mfr compare folder.

usage: allocation_summary.py OUT_DIR [SECONDS]
    reads OUT_DIR/*/results.json, writes OUT_DIR/summary.md and OUT_DIR/summary.html
    (SECONDS: the run time, shown in both)

A case is one scene x view x budget x compositing rule. Per method:
  - MSE / optimal and FLIP / optimal: the geometric mean over the cases where both the method's
    and optimal's value are defined and above 0 (how many is in the `cases` column);
  - failed: the cases where the method could not run (e.g. a share below one node per pixel);
  - wins: for each other method, in how many cases this method's MSE is strictly lower (ties and
    cases where either failed are not counted).
The tables are given for all cases, and per compositing rule. Then one table per rule with a
column per budget: each method's MSE / optimal there and the cases that ran / were refused (a
refusal is a budget below what the method needs, e.g. one node per covered pixel under kbuffer
compositing; under hybrid compositing the per-pixel methods take any share, issue 28).
"""
import glob
import html
import json
import math
import os
import sys
from collections import defaultdict


def geomean(values):
    values = [v for v in values if v is not None and v > 0 and math.isfinite(v)]
    if not values:
        return None, 0
    return math.exp(sum(math.log(v) for v in values) / len(values)), len(values)


def load(out):
    """cases[(folder, budget_label)] = {"compositing": rule, "runs": {method: run}}"""
    cases = {}
    order = []
    for path in sorted(glob.glob(os.path.join(out, "*", "results.json"))):
        folder = os.path.basename(os.path.dirname(path))
        r = json.load(open(path))
        for b in r["budgets"]:
            key = (folder, b["budget_label"])
            runs = {run["name"]: run for run in b["methods"]}
            rule = r["compositing"]
            cases[key] = {"compositing": rule, "runs": runs, "scene": r["scene"]}
            for name in runs:
                if name not in order:
                    order.append(name)
    return cases, order


def value(run, key):
    if run is None or "error" in run:
        return None
    return run.get(key)


def table(cases, methods):
    """rows of (method, mse ratio, flip ratio, n, failed, wins{other: count}, pairs{other: n})"""
    rows = []
    for m in methods:
        mse, flip, failed = [], [], 0
        for c in cases.values():
            run, opt = c["runs"].get(m), c["runs"].get("optimal")
            if run is None:
                continue
            if "error" in run:
                failed += 1
                continue
            for key, acc in (("mse_linear", mse), ("flip_mean", flip)):
                a, o = value(run, key), value(opt, key)
                if a is not None and o is not None and a > 0 and o > 0:
                    acc.append(a / o)
        gm_mse, n_mse = geomean(mse)
        gm_flip, _ = geomean(flip)
        wins, pairs = {}, {}
        for other in methods:
            if other == m:
                continue
            w = n = 0
            for c in cases.values():
                a, b = value(c["runs"].get(m), "mse_linear"), value(c["runs"].get(other), "mse_linear")
                if a is None or b is None:
                    continue
                n += 1
                w += a < b
            wins[other], pairs[other] = w, n
        rows.append((m, gm_mse, gm_flip, n_mse, failed, wins, pairs))
    return rows


def ratio_text(v):
    return "n/a" if v is None else "%.2f" % v


def budget_key(label):
    """budget labels in numeric order ("10%" before "25%"); absolute ones after, as text"""
    try:
        return (0, float(label.rstrip("%")), label) if label.endswith("%") else (1, 0.0, label)
    except ValueError:
        return (1, 0.0, label)


def by_budget(cases, methods, rule):
    """per budget of `rule`: {method: (mse ratio, ran, refused)}"""
    budgets = sorted({k[1] for k, c in cases.items() if c["compositing"] == rule}, key=budget_key)
    out = []
    for b in budgets:
        subset = {k: c for k, c in cases.items() if c["compositing"] == rule and k[1] == b}
        cells = {}
        for m in methods:
            ran = refused = 0
            ratios = []
            for c in subset.values():
                run, opt = c["runs"].get(m), c["runs"].get("optimal")
                if run is None:
                    continue
                if "error" in run:
                    refused += 1
                    continue
                ran += 1
                a, o = value(run, "mse_linear"), value(opt, "mse_linear")
                if a is not None and o is not None and a > 0 and o > 0:
                    ratios.append(a / o)
            cells[m] = (geomean(ratios)[0], ran, refused)
        out.append((b, cells))
    return out


def budget_markdown(rule, columns, methods):
    lines = ["", "### %s compositing by budget: MSE / optimal (cases ran / refused)" % rule, "",
             "| method | " + " | ".join(b for b, _ in columns) + " |",
             "|---" * (1 + len(columns)) + "|"]
    for m in methods:
        cells = []
        for _, c in columns:
            ratio, ran, refused = c[m]
            cells.append("%s (%d / %d)" % (ratio_text(ratio), ran, refused))
        lines.append("| %s | %s |" % (m, " | ".join(cells)))
    return lines


def budget_html(rule, columns, methods):
    h = ["<h2>%s compositing by budget: MSE / optimal (cases ran / refused)</h2>" % html.escape(rule),
         "<table><tr><th>method</th>" + "".join("<th>%s</th>" % html.escape(b) for b, _ in columns)
         + "</tr>"]
    for m in methods:
        h.append("<tr><td><code>%s</code></td>%s</tr>" % (html.escape(m), "".join(
            "<td>%s (%d / %d)</td>" % (ratio_text(c[m][0]), c[m][1], c[m][2]) for _, c in columns)))
    h.append("</table>")
    return h


def markdown(title, rows, methods):
    lines = ["", "### " + title, "",
             "| method | MSE / optimal | FLIP / optimal | cases | failed | " +
             " | ".join("wins vs " + o for o in methods) + " |",
             "|---" * (5 + len(methods)) + "|"]
    for m, gm_mse, gm_flip, n, failed, wins, pairs in rows:
        cells = ["-" if o == m else "%d/%d" % (wins[o], pairs[o]) for o in methods]
        lines.append("| %s | %s | %s | %d | %d | %s |" % (m, ratio_text(gm_mse), ratio_text(gm_flip),
                                                          n, failed, " | ".join(cells)))
    return lines


def html_table(title, rows, methods):
    h = ["<h2>%s</h2>" % html.escape(title), "<table><tr><th>method</th><th>MSE / optimal</th>"
         "<th>FLIP / optimal</th><th>cases</th><th>failed</th>" +
         "".join("<th>wins vs %s</th>" % html.escape(o) for o in methods) + "</tr>"]
    for m, gm_mse, gm_flip, n, failed, wins, pairs in rows:
        h.append("<tr><td><code>%s</code></td><td>%s</td><td>%s</td><td>%d</td><td>%d</td>%s</tr>" % (
            html.escape(m), ratio_text(gm_mse), ratio_text(gm_flip), n, failed,
            "".join("<td>-</td>" if o == m else "<td>%d/%d</td>" % (wins[o], pairs[o])
                    for o in methods)))
    h.append("</table>")
    return h


def main(out, seconds=None):
    cases, methods = load(out)
    if not cases:
        print("allocation_summary: no results.json under %s" % out, file=sys.stderr)
        return 1
    folders = sorted({k[0] for k in cases})
    budgets = sorted({k[1] for k in cases}, key=budget_key)
    rules = sorted({c["compositing"] for c in cases.values()})
    scenes = sorted({c["scene"] for c in cases.values()})
    sections = [("all cases (%d)" % len(cases), cases)]
    for rule in rules:
        subset = {k: c for k, c in cases.items() if c["compositing"] == rule}
        sections.append(("%s compositing (%d cases)" % (rule, len(subset)), subset))
    md = ["# Allocation evaluation", "",
          "%d scenes, %d compare runs (scene x view x rule), budgets %s, rules %s; %d cases." % (
              len(scenes), len(folders), ", ".join(budgets), ", ".join(rules), len(cases)),
          "Ratios: geometric mean over the cases where both values are defined and above 0; "
          "wins: cases with strictly lower MSE than the other method / cases where both ran."]
    if seconds is not None:
        md.append("Run time: %s s." % seconds)
    page = ["<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\">"
            "<title>mfr allocation evaluation</title><style>body{font-family:sans-serif;margin:2em}"
            "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:2px 6px;"
            "text-align:right}td:first-child{text-align:left}</style></head><body>",
            "<h1>Allocation evaluation</h1>", "<p>%s</p>" % html.escape(" ".join(md[2:]))]
    for title, subset in sections:
        rows = table(subset, methods)
        md += markdown(title, rows, methods)
        page += html_table(title, rows, methods)
    for rule in rules:
        columns = by_budget(cases, methods, rule)
        md += budget_markdown(rule, columns, methods)
        page += budget_html(rule, columns, methods)
    page.append("<h2>Reports</h2><ul>")
    for f in folders:
        page.append("<li><a href=\"%s/report.html\">%s</a></li>" % (html.escape(f), html.escape(f)))
    page.append("</ul></body></html>")
    with open(os.path.join(out, "summary.md"), "w") as f:
        f.write("\n".join(md) + "\n")
    with open(os.path.join(out, "summary.html"), "w") as f:
        f.write("\n".join(page) + "\n")
    print("\n".join(md))
    return 0


if __name__ == "__main__":
    if len(sys.argv) < 2:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    sys.exit(main(sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else None))
