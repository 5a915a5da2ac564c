"""Models and datasets a hostile user writes (issue 49 rows 1, 14 and 21): metadata nested
200,000 levels deep killed the interpreter (a stack overflow in C++) in check_dkb(),
render(model=...) and load_dataset(); a dataset's name that is not UTF-8 raised a raw
UnicodeDecodeError; save_dataset wrote a target of 2.0 that load_dataset then refused. Each case
runs in a child interpreter, so a crash fails the test instead of the whole run."""

import os
import struct
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import mfr

TOO_DEEP = "JSON nested deeper than 64 levels"
DEEP_METADATA = '{"features": ' + "[" * 200000 + "0" + "]" * 200000 + "}"  # 400 KB < 1 MiB


def run_child(code, *args):
    """Runs `code` in a fresh interpreter (the same mfr module); returns (returncode, stdout)."""
    proc = subprocess.run([sys.executable, "-c", textwrap.dedent(code), *map(str, args)],
                          capture_output=True, text=True, timeout=120, env=os.environ.copy())
    return proc.returncode, proc.stdout.strip() + proc.stderr.strip()


# prints "<exception type>: <message>" of each call, or "ok"
CATCH = """
import sys, numpy as np, mfr
def attempt(call):
    try:
        call()
        print("ok")
    except Exception as e:
        print(type(e).__name__ + ": " + str(e))
"""


def dataset_bytes(scenes, metadata, targets):
    """A .mfrds file byte by byte (include/mfr/learn/dataset.hpp): one sample per target."""
    out = b"MFRDS\0\0\0" + struct.pack("<IIII", 2, 12, 1, len(scenes))
    for name in scenes:
        out += struct.pack("<I", len(name)) + name
    out += struct.pack("<I", len(metadata)) + metadata + struct.pack("<Q", len(targets))
    for t in targets:
        out += struct.pack("<4I", 0, 0, 0, 0) + struct.pack("<12f", *([0.0] * 12))
        out += struct.pack("<f", t)
    return out


def small_model():
    return mfr.make_model([np.zeros((4, 12)), np.zeros((1, 4))], [np.zeros(4), np.zeros(1)],
                          metadata="{}")


def test_deep_model_metadata_is_an_error_not_a_crash(tmp_path):
    # a .mfrnn whose metadata is 200,000 levels deep: the model's bytes with the metadata swapped
    good = small_model().to_bytes()
    assert good.endswith(struct.pack("<I", 2) + b"{}")
    deep = tmp_path / "deep.mfrnn"
    deep.write_bytes(good[:-6] + struct.pack("<I", len(DEEP_METADATA)) + DEEP_METADATA.encode())
    code, out = run_child(CATCH + """
attempt(lambda: mfr.load_model(sys.argv[1]))
attempt(lambda: mfr.render("procedural:layers", width=16, height=16, method="dkb",
                           budget="64KB", model=sys.argv[1]))
w, b = [np.zeros((4, 12)), np.zeros((1, 4))], [np.zeros(4), np.zeros(1)]
deep = '{"features": ' + "[" * 200000 + "0" + "]" * 200000 + "}"
attempt(lambda: mfr.make_model(w, b, metadata=deep).check_dkb())
""", deep)
    assert code == 0, out
    lines = out.splitlines()
    assert len(lines) == 3, out
    for line in lines[:2]:
        assert line.startswith("Error: ") and "deep.mfrnn" in line and TOO_DEEP in line, line
    # a model made in memory is refused when made: check_dkb and render never see it
    assert lines[2].startswith("ValueError: make_model(): metadata: " + TOO_DEEP), lines[2]


def test_deep_dataset_metadata_is_an_error_not_a_crash(tmp_path):
    deep = tmp_path / "deep.mfrds"
    deep.write_bytes(dataset_bytes([b"scene"], DEEP_METADATA.encode(), [0.5]))
    code, out = run_child(CATCH + """
attempt(lambda: mfr.load_dataset(sys.argv[1]))
attempt(lambda: mfr.load_dataset(sys.argv[1], check=False))
""", deep)
    assert code == 0, out
    for line in out.splitlines():
        assert line.startswith("Error: dataset ") and "deep.mfrds" in line, line
        assert TOO_DEEP in line, line
    with pytest.raises(ValueError, match="metadata: " + TOO_DEEP):
        mfr.save_dataset(tmp_path / "w.mfrds", np.zeros((1, 12)), np.zeros(1),
                         metadata=DEEP_METADATA)
    assert not (tmp_path / "w.mfrds").exists()


def test_dataset_text_that_is_not_utf8_is_one_mfr_error(tmp_path):
    name = tmp_path / "name.mfrds"
    name.write_bytes(dataset_bytes([b"a\xffb"], b"{}", [0.5]))
    with pytest.raises(mfr.Error, match=r"name\.mfrds: scene 0's name is not valid UTF-8"):
        mfr.load_dataset(name)
    meta = tmp_path / "meta.mfrds"
    meta.write_bytes(dataset_bytes([b"scene"], b'{"note": "\xff"}', [0.5]))
    with pytest.raises(mfr.Error, match=r"meta\.mfrds: metadata is not valid UTF-8"):
        mfr.load_dataset(meta)


def test_save_dataset_refuses_what_load_dataset_refuses(tmp_path):
    # a target of 2.0: the range check of the reader, before anything is written
    out = tmp_path / "two.mfrds"
    with pytest.raises(ValueError) as e:
        mfr.save_dataset(out, np.zeros((3, 12)), np.array([0.5, 2.0, 1.0]))
    assert str(e.value) == "save_dataset(): targets[1]: target is 2, outside [0, 1]"
    with pytest.raises(ValueError, match=r"targets\[0\]: target is -0\.5, outside \[0, 1\]"):
        mfr.save_dataset(out, np.zeros((1, 12)), np.array([-0.5]))
    features = np.zeros((2, 12))
    features[1, 7] = np.inf
    with pytest.raises(ValueError, match=r"features\[1\]: feature 7 is inf, not a finite number"):
        mfr.save_dataset(out, features, np.zeros(2))
    assert not out.exists()
    # the bounds themselves are valid, and read back
    mfr.save_dataset(out, np.zeros((2, 12)), np.array([0.0, 1.0]))
    assert list(mfr.load_dataset(out).targets) == [0.0, 1.0]
