"""mfr.metrics against `mfr metrics --json`, its inputs (paths, uint8 and float arrays), its FLIP
map, and errors; PNG and sRGB helpers."""

import json
import math
import re

import numpy as np
import pytest

import mfr

W, H = 48, 40


@pytest.fixture(scope="module")
def pair(tmp_path_factory):
    d = tmp_path_factory.mktemp("metrics")
    scene = mfr.load_scene("procedural:spheres")
    reference = mfr.render(scene, width=W, height=H)
    test = mfr.render(scene, method="fkb", k=1, width=W, height=H)
    mfr.write_png(d / "ref.png", reference.srgb)
    mfr.write_png(d / "test.png", test.srgb)
    return d, reference, test


def test_metrics_equal_cli_json(pair, run_cli):
    d, reference, test = pair
    cli = json.loads(run_cli("metrics", d / "ref.png", d / "test.png", "--json").stdout)
    m = mfr.metrics(str(d / "ref.png"), str(d / "test.png"))
    for key in ("width", "height", "mse_linear", "mse_srgb", "psnr_linear", "psnr_srgb",
                "flip_mean", "flip_median", "flip_p95", "flip_p99", "flip_max",
                "pixels_per_degree"):
        assert m[key] == cli[key], key
    assert m["mse"] == m["mse_linear"] and m["psnr"] == m["psnr_linear"]
    assert m["mse_linear"] > 0 and 0 < m["flip_mean"] < 1
    # arrays give what their files give: the sRGB8 pixels, and linear floats encoded as written
    assert mfr.metrics(reference.srgb, test.srgb)["flip_mean"] == m["flip_mean"]
    assert mfr.metrics(reference.image, test.image)["mse_srgb"] == m["mse_srgb"]
    assert mfr.metrics(reference.srgb[..., :3], d / "test.png")["psnr_srgb"] == m["psnr_srgb"]


def test_flip_map(pair, run_cli):
    d, reference, test = pair
    m = mfr.metrics(reference.srgb, test.srgb, ppd=30.0)
    fmap = m["flip_map"]
    assert fmap.shape == (H, W) and fmap.dtype == np.float32
    assert np.all((fmap >= 0) & (fmap <= 1))
    assert m["flip_mean"] == pytest.approx(float(fmap.astype(np.float64).mean()), rel=1e-6)
    assert m["flip_max"] == pytest.approx(float(fmap.max()))
    assert m["pixels_per_degree"] == 30.0
    cli = json.loads(run_cli("metrics", d / "ref.png", d / "test.png", "--json", "--ppd", 30)
                     .stdout)
    assert m["flip_mean"] == cli["flip_mean"]
    # LDR-FLIP is symmetric
    swapped = mfr.metrics(test.srgb, reference.srgb, ppd=30.0)["flip_map"]
    assert np.array_equal(swapped, fmap)


def test_identical_images():
    image = mfr.render("procedural:bottles", width=W, height=H).srgb
    m = mfr.metrics(image, image.copy())
    assert m["mse_linear"] == 0 and m["mse_srgb"] == 0
    assert math.isinf(m["psnr_linear"]) and math.isinf(m["psnr_srgb"])
    assert m["flip_mean"] == 0 and not m["flip_map"].any()


def test_metrics_errors(tmp_path, pair, cli_error):
    d, reference, test = pair
    with pytest.raises(mfr.Error, match="same size"):
        mfr.metrics(reference.srgb, test.srgb[:-1])
    with pytest.raises(mfr.Error, match="ppd"):
        mfr.metrics(reference.srgb, test.srgb, ppd=0)
    missing = tmp_path / "missing.png"
    with pytest.raises(mfr.Error) as e:
        mfr.metrics(str(missing), d / "test.png")
    assert str(e.value) == cli_error("metrics", missing, d / "test.png")
    with pytest.raises(ValueError, match="3 or 4 channels"):
        mfr.metrics(reference.srgb[..., :2], test.srgb[..., :2])
    with pytest.raises(ValueError, match="dimensions"):
        mfr.metrics(reference.srgb[..., 0], test.srgb[..., 0])
    with pytest.raises(ValueError, match="dtype"):
        mfr.metrics(reference.srgb.astype(np.int64), test.srgb.astype(np.int64))


def test_non_finite_values_are_an_error_naming_the_image_and_pixel(tmp_path):
    black = np.zeros((H, W, 3), dtype=np.float32)
    nan = np.full((H, W, 3), np.nan, dtype=np.float32)
    # before: MSE 0 and PSNR inf (NaN encoded as black)
    with pytest.raises(mfr.Error, match=r"^test: pixel \(0, 0\) is not finite \(nan in r\): "
                                        r"the image must hold finite values$"):
        mfr.metrics(black, nan)
    bad = black.copy()
    bad[2, 5, 1] = np.inf
    with pytest.raises(mfr.Error, match=r"^reference: pixel \(5, 2\) is not finite \(inf in g\)"):
        mfr.metrics(bad, black)
    bad[2, 5, 1] = -np.inf
    with pytest.raises(mfr.Error, match=r"^image: pixel \(5, 2\) is not finite \(-inf in g\)"):
        mfr.write_png(tmp_path / "never.png", bad.astype(np.float64))
    assert not (tmp_path / "never.png").exists()


def test_png_and_srgb_helpers(tmp_path):
    rng = np.random.default_rng(1)
    rgba = rng.integers(0, 256, size=(H, W, 4), dtype=np.uint8)
    mfr.write_png(tmp_path / "a.png", rgba)
    back = mfr.read_png(str(tmp_path / "a.png"))
    assert back.shape == (H, W, 4) and back.dtype == np.uint8 and np.array_equal(back, rgba)
    rgb = rgba[..., :3]
    mfr.write_png(tmp_path / "b.png", rgb)  # strided view: alpha becomes 255
    back = mfr.read_png(tmp_path / "b.png")
    assert np.array_equal(back[..., :3], rgb) and np.all(back[..., 3] == 255)
    # decode then encode is the identity on sRGB8 codes
    linear = mfr.decode_srgb(rgb)
    assert linear.shape == (H, W, 3) and linear.dtype == np.float32
    assert np.array_equal(mfr.encode_srgb(linear)[..., :3], rgb)
    with pytest.raises(mfr.Error, match="missing.png"):
        mfr.read_png(str(tmp_path / "missing.png"))
    (tmp_path / "file").write_text("a file, not a folder")
    with pytest.raises(mfr.Error, match="cannot write PNG"):
        mfr.write_png(tmp_path / "file" / "x.png", rgba)


def test_image_files_are_named_by_their_format(tmp_path):
    rgb = np.zeros((H, W, 3), np.uint8)
    # a PNG is never written under another name (as `mfr render -o x.jpg` is refused)
    for name in ("x.jpg", "x.exr", "x.pfm", "x"):
        with pytest.raises(ValueError, match=r"^write_png\(\): path '.*" + re.escape(name) +
                           r"': .*\(accepted: \.png\)$"):
            mfr.write_png(tmp_path / name, rgb)
        assert not (tmp_path / name).exists()
    mfr.write_png(tmp_path / "upper.PNG", rgb)
    assert (tmp_path / "upper.PNG").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # write_pfm: linear floats as they are, rows bottom to top, little-endian (scale -1.0)
    rng = np.random.default_rng(3)
    linear = (rng.random((H, W, 3)) * 4.0).astype(np.float32)  # above 1: not clamped
    mfr.write_pfm(tmp_path / "a.pfm", linear)
    data = (tmp_path / "a.pfm").read_bytes()
    header = f"PF\n{W} {H}\n-1.0\n".encode()
    assert data[:len(header)] == header and len(data) == len(header) + H * W * 12
    back = np.frombuffer(data[len(header):], dtype="<f4").reshape(H, W, 3)[::-1]
    assert np.array_equal(back, linear)
    for name in ("a.png", "a.PFM.txt"):
        with pytest.raises(ValueError, match=r"^write_pfm\(\): path .*\(accepted: \.pfm\)$"):
            mfr.write_pfm(tmp_path / name, linear)
    with pytest.raises(ValueError, match=r"^write_pfm\(\): image: expected floating-point"):
        mfr.write_pfm(tmp_path / "b.pfm", rgb)
    bad = linear.copy()
    bad[1, 2, 0] = np.nan
    with pytest.raises(mfr.Error, match=r"^image: pixel \(2, 1\) is not finite"):
        mfr.write_pfm(tmp_path / "b.pfm", bad)
    assert not (tmp_path / "b.pfm").exists()
