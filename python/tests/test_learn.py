"""Models (.mfrnn) and datasets (.mfrds) as numpy arrays: the round trip numpy -> .mfrnn -> dkb
render gives the image of the C++-trained model with the same weights, the library's forward pass
equals numpy's, datasets from `mfr dataset` read and write back byte for byte; errors."""

import json
import os

import numpy as np
import pytest

import mfr

W, H = 40, 32
SCENE = "procedural:smoke"  # 29k fragments over 436 of the 40 x 32 pixels
BUDGET = "64KB"  # about 3000 fragment slots: the allocation matters


@pytest.fixture(scope="module")
def default_model_path(source_dir):
    return os.path.join(source_dir, "models", "dkb-default.mfrnn")


def numpy_forward(weights, biases, x):
    """The network dkb runs (ReLU hidden layers, sigmoid output) in numpy, float64."""
    a = np.asarray(x, dtype=np.float64)
    for i, (w, b) in enumerate(zip(weights, biases)):
        a = a @ np.asarray(w, dtype=np.float64).T + np.asarray(b, dtype=np.float64)
        a = np.maximum(a, 0) if i < len(weights) - 1 else 1 / (1 + np.exp(-a))
    return a


def test_builtin_model_is_the_shipped_file(default_model_path):
    builtin = mfr.builtin_model()
    assert builtin.sizes == [12, 128, 64, 1] == list(mfr.DKB_LAYERS)
    assert [w.shape for w in builtin.weights] == [(128, 12), (64, 128), (1, 64)]
    assert [b.shape for b in builtin.biases] == [(128,), (64,), (1,)]
    assert all(w.dtype == np.float32 and not w.flags.writeable for w in builtin.weights)
    assert builtin.parameter_count == 12 * 128 + 128 + 128 * 64 + 64 + 64 + 1
    meta = json.loads(builtin.metadata)
    assert meta["features"] == mfr.FEATURE_SET
    with open(default_model_path, "rb") as f:
        shipped = f.read()
    assert builtin.to_bytes() == shipped
    assert mfr.load_model(default_model_path).to_bytes() == shipped
    builtin.check_dkb()


def test_numpy_round_trip_renders_like_the_cpp_trained_model(tmp_path, run_cli,
                                                             default_model_path):
    # the C++-trained weights (mfr train) through numpy float64 and back into a new file
    trained = mfr.load_model(default_model_path)
    weights = [np.array(w, dtype=np.float64) for w in trained.weights]
    biases = [np.array(b, dtype=np.float64) for b in trained.biases]
    copy = tmp_path / "from_numpy.mfrnn"
    mfr.save_model(copy, weights, biases, metadata=trained.metadata)
    with open(default_model_path, "rb") as f:
        assert copy.read_bytes() == f.read()  # the same file, byte for byte
    # dkb with the numpy-saved model (Python) == dkb with the original file (CLI)
    run_cli("render", SCENE, "--width", W, "--height", H, "-m", "dkb", "-M", BUDGET,
            "--model", default_model_path, "--quiet", "-o", tmp_path / "cli.png")
    r = mfr.render(SCENE, method="dkb", budget=BUDGET, width=W, height=H, model=str(copy))
    mfr.write_png(tmp_path / "py.png", r.srgb)
    assert (tmp_path / "py.png").read_bytes() == (tmp_path / "cli.png").read_bytes()
    # and the built-in model (no model=) is that model
    assert np.array_equal(mfr.render(SCENE, method="dkb", budget=BUDGET, width=W, height=H).srgb,
                          r.srgb)


def test_a_model_made_in_numpy_runs_in_dkb(tmp_path, run_cli):
    rng = np.random.default_rng(5)
    sizes = mfr.DKB_LAYERS
    weights = [rng.normal(0, np.sqrt(2 / sizes[i]), size=(sizes[i + 1], sizes[i]))
               for i in range(3)]
    biases = [rng.normal(0, 0.1, size=sizes[i + 1]) for i in range(3)]
    path = tmp_path / "numpy.mfrnn"
    model = mfr.save_model(path, weights, biases)
    meta = json.loads(model.metadata)
    assert meta["features"] == mfr.FEATURE_SET and meta["target"] == mfr.TARGET_SCALING
    assert meta["layers"] == [12, 128, 64, 1]
    model.check_dkb()
    # stored as float32
    for w, w32 in zip(weights, model.weights):
        assert np.array_equal(w.astype(np.float32), w32)
    # the library's forward pass is numpy's
    x = rng.random((300, 12), dtype=np.float32)
    y = model.predict(x)
    assert y.shape == (300, 1) and y.dtype == np.float32
    np.testing.assert_allclose(y, numpy_forward(model.weights, model.biases, x), rtol=1e-5,
                               atol=1e-6)
    # the CLI reads the file; Python renders with the in-memory model: the same image, and not the
    # built-in model's allocation
    run_cli("render", SCENE, "--width", W, "--height", H, "-m", "dkb-fill", "-M", BUDGET,
            "--model", path, "--quiet", "-o", tmp_path / "cli.png", "--stats-json",
            tmp_path / "s.json")
    r = mfr.render(SCENE, method="dkb-fill", budget=BUDGET, width=W, height=H, model=model)
    assert np.array_equal(mfr.read_png(tmp_path / "cli.png"), r.srgb)
    builtin = mfr.render(SCENE, method="dkb-fill", budget=BUDGET, width=W, height=H)
    assert not np.array_equal(builtin.k_map, r.k_map)
    assert mfr.load_model(path).to_bytes() == model.to_bytes()


def test_model_errors(tmp_path, default_model_path, cli_error):
    w = [np.zeros((4, 12)), np.zeros((1, 4))]
    b = [np.zeros(4), np.zeros(1)]
    with pytest.raises(ValueError, match="previous layer has 4 outputs"):
        mfr.make_model([np.zeros((4, 12)), np.zeros((1, 5))], b)
    with pytest.raises(ValueError, match=r"biases\[1\]: expected shape \(1,\)"):
        mfr.make_model(w, [np.zeros(4), np.zeros(2)])
    with pytest.raises(ValueError, match="finite"):
        mfr.make_model([np.full((4, 12), np.nan), np.zeros((1, 4))], b)
    with pytest.raises(ValueError, match="one per layer"):
        mfr.make_model(w, b[:1])
    # a network dkb cannot use
    small = mfr.make_model([np.zeros((4, 3)), np.zeros((1, 4))], b)
    with pytest.raises(mfr.Error, match="needs 12 inputs and 1 output"):
        small.check_dkb()
    with pytest.raises(mfr.Error, match="needs 12 inputs"):
        mfr.render(SCENE, method="dkb", budget=BUDGET, width=W, height=H, model=small)
    foreign = mfr.make_model(w, b, metadata={"note": "no feature set"})
    foreign_meta = json.loads(foreign.metadata)
    assert foreign_meta["features"] == mfr.FEATURE_SET  # added to a dict's metadata
    verbatim = mfr.make_model(w, b, metadata="{}")
    with pytest.raises(mfr.Error, match="does not declare the feature set"):
        mfr.render(SCENE, method="dkb", budget=BUDGET, width=W, height=H, model=verbatim)
    # files: the library's messages, as the CLI prints them
    missing = tmp_path / "missing.mfrnn"
    with pytest.raises(mfr.Error) as e:
        mfr.load_model(missing)
    assert str(e.value) == cli_error("render", SCENE, "-m", "dkb", "-M", BUDGET, "--model",
                                     missing, "-o", tmp_path / "x.png")
    truncated = tmp_path / "truncated.mfrnn"
    with open(default_model_path, "rb") as f:
        truncated.write_bytes(f.read()[:100])
    with pytest.raises(mfr.Error, match="truncated"):
        mfr.load_model(truncated)
    with pytest.raises(mfr.Error, match="truncated"):
        mfr.render(SCENE, method="dkb", budget=BUDGET, width=W, height=H, model=truncated)


@pytest.fixture(scope="module")
def dataset_file(tmp_path_factory, run_cli):
    path = tmp_path_factory.mktemp("dataset") / "tiny.mfrds"
    run_cli("dataset", "procedural:layers?k=4&r=2", "procedural:smoke?count=20", "--width", 32,
            "--height", 32, "--orbit", 2, "--budget-steps", 3, "--quiet", "-o", path)
    return path


def fnv1a64(data: bytes) -> str:
    h = 0xCBF29CE484222325
    for byte in data:
        h = ((h ^ byte) * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return f"{h:016x}"


def test_dataset_arrays(dataset_file):
    data = mfr.load_dataset(dataset_file)
    n = len(data)
    assert n > 50
    assert data.features.shape == (n, 12) and data.features.dtype == np.float32
    assert data.targets.shape == (n,) and data.targets.dtype == np.float32
    for column in (data.scene, data.view, data.budget_step, data.pixel):
        assert column.shape == (n,) and column.dtype == np.uint32
        assert not column.flags.writeable  # views of the loaded samples, not copies
    assert data.scenes == ["procedural:layers?k=4&r=2", "procedural:smoke?count=20"]
    assert set(np.unique(data.scene)) == {0, 1}
    assert set(np.unique(data.view)) == {0, 1} and set(np.unique(data.budget_step)) == {0, 1, 2}
    assert data.pixel.max() < 32 * 32
    assert np.all((data.targets >= 0) & (data.targets <= 1)) and data.targets.max() == 1
    assert np.all(np.isfinite(data.features))
    assert data.metadata["features"] == mfr.FEATURE_SET
    assert data.metadata["generator"] == "mfr dataset"
    assert data.file_hash == fnv1a64(dataset_file.read_bytes())


def test_dataset_round_trip(tmp_path, dataset_file):
    data = mfr.load_dataset(dataset_file)
    mfr.save_dataset(tmp_path / "copy.mfrds", data)
    assert (tmp_path / "copy.mfrds").read_bytes() == dataset_file.read_bytes()
    # from plain numpy arrays (copies, float64): the same samples back
    mfr.save_dataset(tmp_path / "numpy.mfrds", np.array(data.features, dtype=np.float64),
                     np.array(data.targets), data.scenes, scene=np.array(data.scene),
                     view=data.view, budget_step=data.budget_step, pixel=data.pixel)
    back = mfr.load_dataset(tmp_path / "numpy.mfrds")
    for name in ("features", "targets", "scene", "view", "budget_step", "pixel"):
        assert np.array_equal(getattr(back, name), getattr(data, name)), name
    assert back.metadata["features"] == mfr.FEATURE_SET
    # the arrays outlive the dataset object that made them
    features = mfr.load_dataset(dataset_file).features
    assert np.array_equal(features, data.features)


def test_dataset_errors(tmp_path, dataset_file, cli_error):
    data = mfr.load_dataset(dataset_file)
    with pytest.raises(ValueError, match=r"features: expected shape \(N, 12\)"):
        mfr.save_dataset(tmp_path / "x.mfrds", data.features[:, :11], data.targets)
    with pytest.raises(ValueError, match="targets"):
        mfr.save_dataset(tmp_path / "x.mfrds", data.features, data.targets[:-1])
    with pytest.raises(ValueError, match="there are 1 scenes"):
        mfr.save_dataset(tmp_path / "x.mfrds", data.features, data.targets, ["only"],
                         scene=data.scene)
    missing = tmp_path / "missing.mfrds"
    with pytest.raises(mfr.Error) as e:
        mfr.load_dataset(missing)
    assert str(e.value) == cli_error("train", missing, "-o", tmp_path / "m.mfrnn")
    stale = tmp_path / "stale.mfrds"
    mfr.save_dataset(stale, data.features, data.targets, data.scenes, scene=data.scene,
                     metadata={"features": "mfr-dkb-features-v0"})
    with pytest.raises(mfr.Error, match="regenerate it with mfr dataset"):
        mfr.load_dataset(stale)
    assert len(mfr.load_dataset(stale, check=False)) == len(data)
    bad = tmp_path / "bad.mfrds"
    bad.write_bytes(b"not a dataset")
    with pytest.raises(mfr.Error, match="bad magic"):
        mfr.load_dataset(bad)
