"""Fixtures of the mfr Python tests: the command line to compare against (--mfr-cli), the source
tree (--mfr-source), and a guard that turns a run that collects nothing or skips anything into a
failure (pytest's exit code 5, "no tests", must never pass silently)."""

import json
import os
import subprocess

import pytest


def pytest_addoption(parser):
    parser.addoption("--mfr-cli", default=os.environ.get("MFR_CLI", ""),
                     help="the mfr executable of the same build (default $MFR_CLI)")
    parser.addoption("--mfr-source", default=os.environ.get("MFR_SOURCE_DIR", ""),
                     help="the mfr source tree (default $MFR_SOURCE_DIR)")


_counts = {"collected": 0, "skipped": 0}


def pytest_collection_finish(session):
    _counts["collected"] = len(session.items)


def pytest_runtest_logreport(report):
    if report.skipped:
        _counts["skipped"] += 1


def pytest_sessionfinish(session, exitstatus):
    # every test is expected to run here: nothing is optional in this build
    if exitstatus == 0 and (_counts["collected"] == 0 or _counts["skipped"] > 0):
        print(f"\nmfr tests: {_counts['collected']} collected, {_counts['skipped']} skipped: "
              "failing the run (no test may be skipped or missing)")
        session.exitstatus = 1
    elif exitstatus == 5:
        session.exitstatus = 1


@pytest.fixture(scope="session")
def cli(pytestconfig):
    path = pytestconfig.getoption("--mfr-cli")
    assert path and os.access(path, os.X_OK), "pass --mfr-cli=BUILD/mfr (or set MFR_CLI)"
    return path


@pytest.fixture(scope="session")
def source_dir(pytestconfig):
    path = pytestconfig.getoption("--mfr-source")
    assert path and os.path.isdir(os.path.join(path, "models")), \
        "pass --mfr-source=SOURCE_TREE (or set MFR_SOURCE_DIR)"
    return path


@pytest.fixture(scope="session")
def run_cli(cli):
    """Runs `mfr ARGS...`; returns the CompletedProcess (text). check: expect exit code 0."""

    def run(*args, check=True):
        proc = subprocess.run([cli, *map(str, args)], capture_output=True, text=True,
                              timeout=120)
        if check:
            assert proc.returncode == 0, f"mfr {' '.join(map(str, args))}: {proc.stderr}"
        return proc

    return run


@pytest.fixture(scope="session")
def cli_error(run_cli):
    """The one-line message of a failing `mfr ARGS...` (without "mfr: error: ")."""

    def error(*args):
        proc = run_cli(*args, check=False)
        assert proc.returncode == 1, proc.stderr
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("mfr: error: "), proc.stderr
        return lines[0][len("mfr: error: "):]

    return error


def without_times(value):
    """A results/stats JSON value without its timing entries (time_ms, total_ms*, time_*_ms)."""
    if isinstance(value, dict):
        return {k: without_times(v) for k, v in value.items()
                if not (k == "time_ms" or k.startswith("total_ms") or (k.startswith("time_") and
                                                                  k.endswith("_ms")))}
    if isinstance(value, list):
        return [without_times(v) for v in value]
    return value


def read_json(path):
    with open(path) as f:
        return json.load(f)
