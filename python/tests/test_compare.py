"""mfr.compare writes the folder `mfr compare` writes for the same options: same files, same PNG
bytes, same results.json and results.csv but for timings; and its errors."""

import csv
import html
import io
import os
import re

import pytest

import mfr
from conftest import read_json, without_times

SCENE = "procedural:bottles?count=3"
SIZE = 32
BUDGETS = ["40KB", "80KB"]
METHODS = ["fkb", "vkb", "dkb"]


@pytest.fixture(scope="module")
def folders(tmp_path_factory, cli):
    import subprocess
    d = tmp_path_factory.mktemp("compare")
    subprocess.run([cli, "compare", SCENE, "--width", str(SIZE), "--height", str(SIZE),
                    "--budget", ",".join(BUDGETS), "--methods", ",".join(METHODS),
                    "--threads", "2", "--out", str(d / "cli"), "--quiet"], check=True)
    results = mfr.compare(SCENE, d / "py", BUDGETS, methods=METHODS, width=SIZE, height=SIZE,
                          threads=2)
    return d / "cli", d / "py", results


def csv_without_times(path):
    rows = list(csv.reader(io.StringIO(path.read_text())))
    keep = [i for i, name in enumerate(rows[0]) if not (name.startswith("time_") or
                                                         name.startswith("total_ms"))]
    return [[row[i] for i in keep] for row in rows]


def test_same_files_and_images(folders):
    cli, py, _ = folders
    files = sorted(os.listdir(cli))
    assert files == sorted(os.listdir(py))
    pngs = [f for f in files if f.endswith(".png")]
    # ground truth, its depth complexity, per run image + flip + k-map, + importance (vkb, dkb),
    # each method under both compositing rules (the default)
    assert len(pngs) == 2 + len(BUDGETS) * 2 * (3 * len(METHODS) + 2)
    for name in pngs:
        assert (cli / name).read_bytes() == (py / name).read_bytes(), name
    assert {"results.json", "results.csv", "report.html"} <= set(files)


def test_same_results(folders):
    cli, py, results = folders
    cli_json, py_json = read_json(cli / "results.json"), read_json(py / "results.json")
    assert results == py_json  # the returned dict is the file
    assert without_times(cli_json) == without_times(py_json)
    assert py_json["mfr_version"] == mfr.__version__
    assert [b["budget_label"] for b in py_json["budgets"]] == BUDGETS
    assert csv_without_times(cli / "results.csv") == csv_without_times(py / "results.csv")
    report = html.unescape((py / "report.html").read_text())
    assert "mfr.compare('procedural:bottles?count=3'" in report
    assert "fkb-kbuffer_40KB.png" in report and "fkb-hybrid_40KB.png" in report


def test_metrics_recomputed_from_the_files(folders):
    _, py, results = folders
    run = results["budgets"][1]["methods"][0]
    m = mfr.metrics(py / results["ground_truth"]["image"], py / run["image"],
                    ppd=results["flip_pixels_per_degree"])
    assert m["flip_mean"] == run["flip_mean"] and m["mse_linear"] == run["mse_linear"]


def test_compare_errors(tmp_path):
    kwargs = dict(width=SIZE, height=SIZE)
    with pytest.raises(mfr.Error, match="method list is empty"):
        mfr.compare(SCENE, tmp_path / "a", "40KB", methods=[], **kwargs)
    with pytest.raises(mfr.Error, match="nosuch"):
        mfr.compare(SCENE, tmp_path / "a", "40KB", methods=["fkb", "nosuch"], **kwargs)
    with pytest.raises(mfr.Error, match="listed twice"):
        mfr.compare(SCENE, tmp_path / "a", ["40KB", "40960"], methods=["fkb"], **kwargs)
    with pytest.raises(mfr.Error, match="none of the methods uses it"):
        mfr.compare(SCENE, tmp_path / "a", "40KB", methods=["fkb"], model="m.mfrnn", **kwargs)
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    with pytest.raises(mfr.Error, match="cannot create the output folder"):
        mfr.compare(SCENE, blocker, "40KB", methods=["fkb"], **kwargs)
    # the ground truth's buffers at this size do not fit: refused before the frame is set up
    with pytest.raises(mfr.Error, match=r"^procedural:hairball: ground truth \(abuffer\): "
                                        r"abuffer at 16384 x 16384 pixels: its per-pixel buffers"):
        mfr.compare("procedural:hairball", tmp_path / "c", "40KB", methods=["fkb"], width=16384,
                    height=16384, memory_limit="1GB")
    # a budget too small for a method is recorded, not raised, with the method's minimum
    r = mfr.compare(SCENE, tmp_path / "b", ["2KB", "80KB"], methods=["fkb"], composite="kbuffer",
                    **kwargs)
    assert r["methods"][0]["error"].startswith("fkb at 2KB: needs at least ")
    assert r["methods"][0]["minimum_bytes"] == SIZE * SIZE * 12
    assert "error" not in r["budgets"][1]["methods"][0]
    # but a comparison where nothing ran raises, once its folder holds the refusals
    with pytest.raises(mfr.Error, match=r"no run succeeded: every method was refused at every "
                                        r"budget \(the smallest budget that runs: fkb-kbuffer at "
                                        r"12.00 KiB; mfr info --methods lists them all\); the "
                                        r"refusals are in "):
        mfr.compare(SCENE, tmp_path / "c", "2KB", methods=["fkb"], **kwargs)
    assert read_json(tmp_path / "c" / "results.json")["methods"][1]["label"] == "fkb-hybrid"


def test_an_old_folder_is_replaced_whole_and_another_never(tmp_path):
    out = tmp_path / "out"
    mfr.compare(SCENE, out, "40KB", methods=["fkb", "vkb"], width=16, height=16)
    assert (out / "vkb-kbuffer_40KB.png").exists()
    # a failing compare (here its ground truth does not fit) leaves the old folder as it was
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    with pytest.raises(mfr.Error, match="memory limit"):
        mfr.compare(SCENE, out, "40KB", methods=["fkb"], width=64, height=64, memory_limit="4KB")
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    # a complete one replaces it whole, as `mfr compare` does: no file of the old one is left
    mfr.compare(SCENE, out, "40KB", methods=["fkb"], width=24, height=24)
    assert read_json(out / "results.json")["width"] == 24
    assert not (out / "vkb-kbuffer_40KB.png").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no staging folder left
    # a folder holding files a comparison does not write is never replaced
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("keep")
    with pytest.raises(mfr.Error, match=r"holds 'notes.txt', which a comparison does not write"):
        mfr.compare(SCENE, tmp_path / "mine", "40KB", methods=["fkb"], width=16, height=16)
    assert (tmp_path / "mine" / "notes.txt").read_text() == "keep"


def test_default_methods_are_the_clis(run_cli):
    help_text = run_cli("compare", "--help").stdout
    default = re.search(r"--methods TEXT +Methods, comma-separated \(default ([a-z0-9+,-]+)\)",
                        help_text)
    assert default, help_text
    assert tuple(default.group(1).split(",")) == mfr.DEFAULT_COMPARE_METHODS


def test_relative_budgets_match_the_cli(tmp_path, cli):
    # a mixed list: the share's bytes are each method's own words + the share of the A-buffer's
    # node bytes, resolved the same way by the module and the command line
    import subprocess
    budgets = ["40KB", "60%"]
    subprocess.run([cli, "compare", SCENE, "--width", str(SIZE), "--height", str(SIZE),
                    "--budget", ",".join(budgets), "--methods", "vkb,kplus-dynamic",
                    "--composite", "kbuffer", "--threads", "2", "--out", str(tmp_path / "cli"),
                    "--quiet"], check=True)
    py = mfr.compare(SCENE, tmp_path / "py", budgets, methods=["vkb", "kplus-dynamic"],
                     width=SIZE, height=SIZE, threads=2, composite="kbuffer")
    cli_json = read_json(tmp_path / "cli" / "results.json")
    assert without_times(cli_json) == without_times(py)
    share = py["budgets"][1]
    assert share["budget_label"] == "60%" and share["budget_percent"] == 60.0
    fragments = py["ground_truth"]["fragments_generated"]
    assert share["budget_bytes"] == 60 * 8 * fragments // 100
    # vkb pays one byte per pixel more than kplus-dynamic (the previous frame's |n.v|), which
    # pays its 4 KiB histogram
    vkb, dynamic = share["methods"]
    assert vkb["budget_bytes"] - dynamic["budget_bytes"] == SIZE * SIZE * 1 - 4096
    with pytest.raises(Exception, match="0%"):
        mfr.compare(SCENE, tmp_path / "bad", ["0%"], methods=["vkb"], width=SIZE, height=SIZE)


def test_temporal_orbit_and_orbit_view_match_the_cli(tmp_path, cli):
    # orbit=N: the CLI's temporal comparison (frames, flicker, plots); orbit_view: one view of it
    import subprocess
    common = ["--width", "24", "--height", "20", "--budget", "50%", "--methods", "fkb,vkb",
              "--threads", "2", "--quiet"]
    subprocess.run([cli, "compare", SCENE, "--orbit", "3", "--orbit-step", "5", *common,
                    "--out", str(tmp_path / "cli_t")], check=True)
    py_t = mfr.compare(SCENE, tmp_path / "py_t", "50%", methods=["fkb", "vkb"], width=24,
                       height=20, threads=2, orbit=3, orbit_step=5)
    cli_t = read_json(tmp_path / "cli_t" / "results.json")
    assert without_times(cli_t) == without_times(py_t)
    assert py_t["frames"] == ["frame_000", "frame_001", "frame_002"]
    for frame in py_t["frames"]:
        assert (tmp_path / "cli_t" / frame / "ground_truth.png").read_bytes() == \
            (tmp_path / "py_t" / frame / "ground_truth.png").read_bytes()
    subprocess.run([cli, "compare", SCENE, "--orbit", "4", "--orbit-view", "2", *common,
                    "--out", str(tmp_path / "cli_v")], check=True)
    py_v = mfr.compare(SCENE, tmp_path / "py_v", "50%", methods=["fkb", "vkb"], width=24,
                       height=20, threads=2, orbit=4, orbit_view=2)
    assert without_times(read_json(tmp_path / "cli_v" / "results.json")) == without_times(py_v)
    with pytest.raises(mfr.Error, match=r"^orbit_step: needs orbit N"):
        mfr.compare(SCENE, tmp_path / "x", "50%", methods=["fkb"], width=24, height=20,
                    orbit_step=5)


def test_sample_counts_as_the_cli_runs_them(tmp_path, cli):
    # sample_counts: the comparison at each count against its own truth, the same figures as
    # `mfr compare --sample-counts` (metrics and statistics but timings)
    import subprocess
    subprocess.run([cli, "compare", SCENE, "--width", str(SIZE), "--height", str(SIZE),
                    "--budget", "80KB", "--methods", "kplus-heap", "--sample-counts", "1,4",
                    "--threads", "2", "--out", str(tmp_path / "cli"), "--quiet"], check=True)
    r = mfr.compare(SCENE, tmp_path / "py", "80KB", methods=["kplus-heap"], width=SIZE,
                    height=SIZE, threads=2, sample_counts=[1, 4])
    cli_counts = read_json(tmp_path / "cli" / "results.json")["sample_counts"]
    assert [c["samples"] for c in r["sample_counts"]] == [1, 4]
    for py_count, cli_count in zip(r["sample_counts"], cli_counts):
        py_run = py_count["budgets"][0]["methods"][0]
        cli_run = cli_count["budgets"][0]["methods"][0]
        assert without_times(py_run) == without_times(cli_run)
        assert py_run["samples"] == py_count["samples"]
    with pytest.raises(mfr.Error, match=r"^sample_counts '4,4': 4 listed twice$"):
        mfr.compare(SCENE, tmp_path / "x", "80KB", methods=["kplus-heap"], width=SIZE,
                    height=SIZE, sample_counts=[4, 4])
    with pytest.raises(mfr.Error, match=r"^sample_counts '3': expected 1, 2, 4 or 8$"):
        mfr.compare(SCENE, tmp_path / "x", "80KB", methods=["kplus-heap"], width=SIZE,
                    height=SIZE, sample_counts=[1, 3])


def test_the_request_is_checked_as_the_cli_checks_it(tmp_path):
    # one CompareRequest for both faces: the same checks, the option spelled the Python way
    kwargs = dict(width=SIZE, height=SIZE, methods=["fkb"])
    with pytest.raises(mfr.Error, match=r"^repeat 0: must be in \[1, 1000\]"):
        mfr.compare(SCENE, tmp_path / "a", "40KB", repeat=0, **kwargs)
    with pytest.raises(mfr.Error, match=r"^warmup -1: must be in \[0, 1000\]"):
        mfr.compare(SCENE, tmp_path / "a", "40KB", warmup=-1, **kwargs)
    with pytest.raises(mfr.Error, match=r"^composite: rule 'hybrid' listed twice"):
        mfr.compare(SCENE, tmp_path / "a", "40KB", composite=["hybrid", "hybrid"], **kwargs)
    with pytest.raises(mfr.Error, match=r"^max_peels: none of the methods peels"):
        mfr.compare(SCENE, tmp_path / "a", "40KB", max_peels=2, **kwargs)
    with pytest.raises(mfr.Error, match=r"^max_peels: must be in \[1, "):
        mfr.compare(SCENE, tmp_path / "a", "40KB", max_peels=0, methods=["peel"], width=SIZE,
                    height=SIZE)
    with pytest.raises(mfr.Error, match=r"^truth_engine: .*'vulkanish'"):
        mfr.compare(SCENE, tmp_path / "a", "40KB", truth_engine="vulkanish", **kwargs)
    with pytest.raises(mfr.Error, match=r"^budgets auto: picks every budget"):
        mfr.compare(SCENE, tmp_path / "a", ["auto", "40KB"], **kwargs)
    assert not (tmp_path / "a").exists()


def test_max_peels_rules_repeats_and_the_table(tmp_path):
    r = mfr.compare(SCENE, tmp_path / "p", "200KB", methods=["peel", "fkb"], width=SIZE,
                    height=SIZE, max_peels=1, composite="kbuffer,hybrid", repeat=2, warmup=0)
    runs = r["methods"]
    # bounded peeling takes both rules: dropped beyond the pass, or blended into a tail
    assert [m["label"] for m in runs] == ["peel-kbuffer", "peel-hybrid", "fkb-kbuffer",
                                          "fkb-hybrid"]
    assert runs[0]["fragments_lost"] > 0 and runs[0]["peel_passes"] == 1
    assert runs[1]["flip_mean"] < runs[0]["flip_mean"]  # the tail keeps what the pass dropped
    for m in runs:
        assert m["repeats"] == 2
        assert m["total_ms_min"] <= m["total_ms"] <= m["total_ms_max"]
    assert r["repeat"] == 2 and r["warmup"] == 0
    rows = r.rows()
    assert [row["label"] for row in rows] == ["abuffer"] + [m["label"] for m in runs]
    assert rows[1]["budget_label"] == "200KB" and rows[0]["budget_label"] == ""
    table = r.table()
    try:
        import pandas
    except ImportError:
        assert table == rows
    else:
        assert isinstance(table, pandas.DataFrame)
        assert list(table["label"]) == [row["label"] for row in rows]
        assert table.loc[1, "flip_mean"] == runs[0]["flip_mean"]


def test_auto_budgets_run_from_the_smallest_minimum_to_the_abuffer(tmp_path, run_cli):
    r = mfr.compare(SCENE, tmp_path / "auto", "auto", methods=["fkb", "kplus-dynamic"],
                    width=SIZE, height=SIZE, composite="kbuffer", repeat=1, warmup=0)
    assert r["budgets_auto"] is True
    sizes = [b["budget_bytes"] for b in r["budgets"]]
    assert len(sizes) >= 2 and sizes == sorted(sizes) and len(set(sizes)) == len(sizes)
    info = run_cli("info", SCENE, "--width", str(SIZE), "--height", str(SIZE), "--methods",
                   "fkb,kplus-dynamic", "--composite", "kbuffer", "--json")
    import json
    table = json.loads(info.stdout)
    views = table["views"] if "views" in table else [table]
    budgets = views[0]["budgets"]
    assert [b["budget_label"] for b in r["budgets"]] == budgets["auto_budgets"]
    minimums = {m["method"]: m["minimum_bytes"] for m in budgets["methods"]}
    smallest = min(minimums, key=minimums.get)
    assert minimums[smallest] <= sizes[0] < 2 * minimums[smallest]
    top = max(budgets["abuffer_bytes"], max(minimums.values()))
    assert top <= sizes[-1] < 2 * top
    # the method of the smallest minimum runs at the first budget, every method at the last
    first = {m["name"]: m for m in r["budgets"][0]["methods"]}
    assert "error" not in first[smallest], first[smallest]
    for m in r["budgets"][-1]["methods"]:
        assert "error" not in m, m
