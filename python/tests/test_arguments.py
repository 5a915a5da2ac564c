"""Every function and method of the module (mfr.__all__) called with arguments it cannot take: an
object of the wrong type, an integer too large for C++ (10**30), a negative integer (-1, a seed or
a size) and NaN (issue 49, row 15).

Each must end in a TypeError, ValueError or OverflowError whose one-line message starts with the
function ("render(): ", "Model.predict(): ", "Scene.cull") and then the parameter, or, for a value
of the right type outside the library's range, in mfr.Error naming the parameter (the command
line's message) -- never pybind11's signature dump ("incompatible function arguments") or "Unable
to cast Python instance", another exception, or a crash. The calls run in a child interpreter
(this file run as a script), one per function, so that a crash fails the test naming the call.
Paths that are not UTF-8 (bytes, or os.fsdecode's surrogate-escaped str) work."""

import functools
import inspect
import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

import mfr

W, H = 8, 6
SCENE = "procedural:bottles?count=1"

# the values each parameter is called with; "wrong type" must be a TypeError
BAD_VALUES = {
    "wrong type": lambda: object(),
    "10**30": lambda: 10**30,
    "-1": lambda: -1,
    "nan": lambda: math.nan,
}

# the public classes that are not functions: their methods and settable properties are swept
# ("Model", "Scene") or they take no arguments from the caller (results, the error, a record)
CLASSES = {"Model", "Scene", "RenderResult", "Error", "Dataset", "CompareResults"}


def valid_calls(work):
    """For each callable of the sweep: a label (what its messages start with), the callable and
    arguments that work, by name (parameters not given keep their defaults)."""
    png = os.path.join(work, "ok.png")
    model_path = os.path.join(work, "ok.mfrnn")
    dataset_path = os.path.join(work, "ok.mfrds")
    rgb = np.zeros((4, 4, 3), np.uint8)
    mfr.write_png(png, rgb)
    weights, biases = [np.zeros((1, 12), np.float32)], [np.zeros(1, np.float32)]
    model = mfr.save_model(model_path, weights, biases)
    features, targets = np.zeros((2, 12), np.float32), np.zeros(2, np.float32)
    mfr.save_dataset(dataset_path, features, targets)
    counter = iter(range(1 << 30))

    def fresh(name):
        return os.path.join(work, f"{name}{next(counter)}")

    scene = mfr.load_scene(SCENE)
    return {
        "render": (mfr.render, lambda: dict(scene=SCENE, width=W, height=H)),
        "compare": (mfr.compare, lambda: dict(scene=SCENE, out=fresh("compare"), budgets="40KB",
                                              methods=["fkb"], width=W, height=H)),
        "load_scene": (mfr.load_scene, lambda: dict(source=SCENE)),
        "metrics": (mfr.metrics, lambda: dict(reference=png, test=rgb)),
        "parse_bytes": (mfr.parse_bytes, lambda: dict(text="20MB")),
        "read_png": (mfr.read_png, lambda: dict(path=png)),
        "write_png": (mfr.write_png, lambda: dict(path=fresh("w") + ".png", image=rgb)),
        "write_pfm": (mfr.write_pfm, lambda: dict(path=fresh("p") + ".pfm",
                                                  image=np.zeros((4, 4, 3), np.float32))),
        "encode_srgb": (mfr.encode_srgb, lambda: dict(image=np.zeros((4, 4, 3), np.float32))),
        "decode_srgb": (mfr.decode_srgb, lambda: dict(image=rgb)),
        "engine_names": (mfr.engine_names, dict),
        "preset_names": (mfr.preset_names, dict),
        "builtin_model": (mfr.builtin_model, dict),
        "make_model": (mfr.make_model, lambda: dict(weights=weights, biases=biases)),
        "save_model": (mfr.save_model, lambda: dict(path=fresh("m") + ".mfrnn", weights=weights,
                                                    biases=biases)),
        "load_model": (mfr.load_model, lambda: dict(path=model_path)),
        "load_dataset": (mfr.load_dataset, lambda: dict(path=dataset_path)),
        "save_dataset": (mfr.save_dataset, lambda: dict(path=fresh("d") + ".mfrds",
                                                        features=features, targets=targets)),
        "Model": (mfr.Model, lambda: dict(weights=weights, biases=biases, metadata="{}")),
        "Model.load": (mfr.Model.load, lambda: dict(path=model_path)),
        "Model.save": (functools.partial(mfr.Model.save, model),
                       lambda: dict(path=fresh("s") + ".mfrnn")),
        "Model.predict": (functools.partial(mfr.Model.predict, model),
                          lambda: dict(features=features)),
        "Model.to_bytes": (functools.partial(mfr.Model.to_bytes, model), dict),
        "Model.check_dkb": (functools.partial(mfr.Model.check_dkb, model), dict),
        # properties: the value assigned is the one parameter
        "Scene.background": (lambda value: setattr(scene, "background", value),
                             lambda: dict(value=(0, 0, 0))),
        "Scene.alpha_override": (lambda value: setattr(scene, "alpha_override", value),
                                 lambda: dict(value=None)),
        "Scene.cull": (lambda value: setattr(scene, "cull", value), lambda: dict(value="none")),
    }


PARAMETER_NAMES = {  # what a property's messages name
    "Scene.background": "background", "Scene.alpha_override": "alpha_override",
    "Scene.cull": "cull",
}


def parameters(function):
    return list(inspect.signature(function).parameters)


def sweep(label, work):
    """The child: every call of `label`'s sweep, one JSON line before (the call) and after (its
    outcome) each, flushed, so that the parent can name a call that crashed the interpreter."""
    function, valid = valid_calls(work)[label]

    def report(**fields):
        print(json.dumps(fields), flush=True)

    def attempt(description, call):
        report(call=description)
        try:
            call()
            report(outcome="ok")
        except BaseException as e:  # noqa: B036 - reported, whatever it is
            kind = "mfr.Error" if isinstance(e, mfr.Error) else type(e).__name__
            report(outcome="raised", kind=kind, message=str(e))

    attempt("valid", lambda: function(**valid()))
    for parameter in parameters(function):
        for value_name, value in BAD_VALUES.items():
            def call(parameter=parameter, value=value):
                arguments = valid()
                arguments[parameter] = value()
                function(**arguments)
            attempt(json.dumps([parameter, value_name]), call)
    if not label.startswith("Scene."):  # an unknown keyword: Python's own error naming the call
        attempt("bogus", lambda: function(**valid(), bogus=1))


def test_all_lists_the_public_api():
    assert len(mfr.__all__) == len(set(mfr.__all__))
    for name in mfr.__all__:
        assert hasattr(mfr, name), name
    public = {name for name, value in vars(mfr).items()
              if not name.startswith("_") and (inspect.isfunction(value) or
                                               inspect.isclass(value) or
                                               inspect.isbuiltin(value))
              and getattr(value, "__module__", "").startswith("mfr")}
    assert public <= set(mfr.__all__), public - set(mfr.__all__)
    assert {"render", "compare", "load_scene", "metrics", "Model", "Scene"} <= set(mfr.__all__)


def swept_labels():
    labels = []
    for name in mfr.__all__:
        value = getattr(mfr, name)
        if name in CLASSES or not callable(value):
            continue
        labels.append(name)
    labels += ["Model", "Model.load", "Model.save", "Model.predict", "Model.to_bytes",
               "Model.check_dkb", "Scene.background", "Scene.alpha_override", "Scene.cull"]
    return labels


def test_every_public_function_is_swept(tmp_path):
    # a function added to mfr.__all__ without a valid call here fails, rather than going unswept
    assert set(swept_labels()) <= set(valid_calls(str(tmp_path)))
    for name in mfr.__all__:
        assert name in CLASSES or not callable(getattr(mfr, name)) or name in swept_labels(), name
    # each function has its real signature (the extension's would have none)
    for label in swept_labels():
        if "." not in label and label != "Model":
            inspect.signature(getattr(mfr, label))
    assert parameters(mfr.Model.predict) == ["self", "features"]
    assert parameters(mfr.Model) == ["weights", "biases", "metadata"]


def check_outcome(label, description, outcome):
    """The rules of the module docstring for one call."""
    what = f"{label} {description}: {outcome}"
    if description == "valid":
        assert outcome["outcome"] == "ok", what
        return
    assert outcome["outcome"] == "raised", what
    kind, message = outcome["kind"], outcome["message"]
    assert "\n" not in message, what
    for dump in ("incompatible function arguments", "Unable to cast", "Invoked with",
                 "PYBIND11", "pybind11"):
        assert dump not in message, what
    if description == "bogus":
        assert kind == "TypeError" and "bogus" in message and label.split(".")[-1] in message, what
        return
    parameter, value = json.loads(description)
    name = PARAMETER_NAMES.get(label, parameter)
    # "render(): width: ...", "Model.predict(): features: ...", a property: "Scene.cull: ..."
    named = message.startswith(label if label.startswith("Scene.") else f"{label}(): {name}")
    if kind in ("TypeError", "ValueError", "OverflowError"):
        assert named, what
    else:
        # a value of the right type that the library refuses: its message, naming the parameter
        assert kind == "mfr.Error" and value not in ("wrong type", "nan"), what
        assert name in message.split(":")[0] or message.startswith(name), what


@pytest.mark.parametrize("label", swept_labels())
def test_wrong_arguments_name_the_function_and_the_parameter(label, tmp_path):
    proc = subprocess.run([sys.executable, __file__, label, str(tmp_path)], capture_output=True,
                          text=True, timeout=240)
    lines = [json.loads(line) for line in proc.stdout.splitlines()]
    assert proc.returncode == 0, (f"{label}: the interpreter died ({proc.returncode}) in the call "
                                  f"{lines[-1] if lines else None}: {proc.stderr[-2000:]}")
    calls = 0
    for call, outcome in zip(lines[::2], lines[1::2]):
        check_outcome(label, call["call"], outcome)
        calls += 1
    assert calls == len(lines) // 2 and len(lines) % 2 == 0
    expected = 1 + 4 * (len(parameters(valid_calls(str(tmp_path))[label][0])))
    assert calls >= expected, (calls, expected)


# --- the messages the issue quotes -------------------------------------------------------------

@pytest.mark.parametrize("call,kind,message", [
    (lambda: mfr.render(SCENE, budget=10**30, method="fkb"), OverflowError,
     "render(): budget: expected an integer in [0, 18446744073709551615], got "
     "1000000000000000000000000000000"),
    (lambda: mfr.render(SCENE, memory_limit=10**30), OverflowError,
     "render(): memory_limit: expected an integer in [0, 18446744073709551615], got "
     "1000000000000000000000000000000"),
    (lambda: mfr.render(SCENE, width=10**30), OverflowError,
     "render(): width: expected an integer in [-2147483648, 2147483647], got "
     "1000000000000000000000000000000"),
    (lambda: mfr.render(SCENE, seed=-1), OverflowError,
     "render(): seed: expected an integer in [0, 18446744073709551615], got -1"),
    (lambda: mfr.load_scene(SCENE, seed=2**64), OverflowError,
     "load_scene(): seed: expected an integer in [0, 18446744073709551615], got "
     "18446744073709551616"),
    (lambda: mfr.render(SCENE, shuffle_draw_order=10**5000), OverflowError,
     "render(): shuffle_draw_order: expected an integer in [0, 18446744073709551615], got an "
     "integer of about 5001 digits"),
    (lambda: mfr.render(SCENE, zoom=math.nan), ValueError,
     "render(): zoom: expected a finite number, got nan"),
    (lambda: mfr.render(SCENE, camera=(0, 0, 1, 0, 0, math.nan)), ValueError,
     "render(): camera[5]: expected a finite number, got nan"),
    (lambda: mfr.render(SCENE, zoom=10**400), OverflowError,
     "render(): zoom: expected a finite number, got an integer of about 401 digits"),
    (lambda: mfr.render(SCENE, width=True), TypeError,
     "render(): width: expected an integer, got bool"),
    (lambda: mfr.render(SCENE, depth_complexity=1), TypeError,
     "render(): depth_complexity: expected True or False, got int"),
    (lambda: mfr.encode_srgb("x"), TypeError,
     "encode_srgb(): image: expected an image array (height, width, channels), got str"),
    (lambda: mfr.decode_srgb(5), TypeError,
     "decode_srgb(): image: expected an image array (height, width, channels), got int"),
    (lambda: mfr.write_png(5, np.zeros((2, 2, 3), np.uint8)), TypeError,
     "write_png(): path: expected a path (str, bytes or os.PathLike), got int"),
    (lambda: mfr.write_png("x.png", None), TypeError,
     "write_png(): image: expected an image array (height, width, channels), got NoneType"),
    (lambda: mfr.builtin_model().predict("x"), TypeError,
     "Model.predict(): features: expected an array of numbers, got str"),
    (lambda: mfr.builtin_model().predict([["a"] * 12]), TypeError,
     "Model.predict(): features: expected an array of numbers, got list of <U1"),
    (lambda: setattr(mfr.load_scene(SCENE), "cull", 5), TypeError,
     "Scene.cull: expected a str, got int"),
    (lambda: mfr.make_model(5, []), TypeError,
     "make_model(): weights: expected a list of weight arrays, got int"),
    (lambda: mfr.make_model([np.zeros((1, 12))], [np.zeros(1)], metadata={"x": math.nan}),
     ValueError, "make_model(): metadata: not JSON: Out of range float values are not JSON "
                 "compliant: nan"),
    (lambda: mfr.save_model("m.mfrnn", [np.zeros((1, 12))], 7), TypeError,
     "save_model(): biases: expected a list of bias arrays, got int"),
    (lambda: mfr.load_model(3.5), TypeError,
     "load_model(): path: expected a path (str, bytes or os.PathLike), got float"),
    (lambda: mfr.load_dataset("x.mfrds", check="yes"), TypeError,
     "load_dataset(): check: expected True or False, got str"),
    (lambda: mfr.save_dataset("d.mfrds", np.zeros((1, 12)), np.zeros(1), scenes="abc"),
     TypeError, "save_dataset(): scenes: expected a list of str, got str"),
    (lambda: mfr.save_dataset("d.mfrds", np.zeros((1, 12)), np.zeros(1), view=[-1]),
     OverflowError, "save_dataset(): view: values must be in [0, 4294967295]"),
    (lambda: mfr.compare(SCENE, "c", 2.5), TypeError,
     "compare(): budgets: expected a budget or a list of budgets, got float"),
    (lambda: mfr.compare(SCENE, "c", ["1MB", 10**30]), OverflowError,
     "compare(): budgets[1]: expected an integer in [0, 18446744073709551615], got "
     "1000000000000000000000000000000"),
    (lambda: mfr.compare(SCENE, "c", "1MB", sample_counts=[1, "4"]), TypeError,
     "compare(): sample_counts[1]: expected an integer, got str"),
    (lambda: mfr.metrics(object(), "b.png"), TypeError,
     "metrics(): reference: expected a PNG path or an image array, got object"),
    (lambda: mfr.metrics("a.png", "b.png", ppd=math.inf), ValueError,
     "metrics(): ppd: expected a finite number, got inf"),
    (lambda: mfr.parse_bytes(b"20MB"), TypeError, "parse_bytes(): text: expected a str, got bytes"),
    (lambda: mfr.read_png("a\0b.png"), ValueError,
     "read_png(): path: a path cannot contain a NUL byte"),
    (lambda: mfr.render(SCENE, method="fkb\udcff"), ValueError,
     "render(): method: expected text, got a str that is not valid Unicode ('fkb\\udcff')"),
])
def test_argument_errors_name_the_function_the_parameter_and_the_value(call, kind, message,
                                                                         tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(kind) as e:
        call()
    assert str(e.value) == message


def test_paths_that_are_not_utf8_work(tmp_path):
    # os.listdir gives such a name as a str with surrogates; bytes name it too: both are the file
    folder = os.fsencode(tmp_path)
    obj = os.path.join(folder, b"tri\xff.obj")
    with open(obj, "wb") as f:
        f.write(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    for source in (obj, os.fsdecode(obj)):
        scene = mfr.load_scene(source)
        assert scene.triangle_count == 1
        assert scene.name == os.fsdecode(obj)
        assert "tri\\udcff.obj" in repr(scene)
        result = mfr.render(source, width=W, height=H)
        assert result.stats["scene"] == os.fsdecode(obj)
        assert mfr.render(scene, width=W, height=H).stats["scene"] == os.fsdecode(obj)
    # a comparison records it in results.json (JSON is UTF-8: the byte as U+FFFD)
    out = os.path.join(folder, b"compare\xfe")
    results = mfr.compare(obj, out, "40KB", methods=["fkb"], width=W, height=H)
    assert os.path.isfile(os.path.join(out, b"results.json"))
    assert results["scene"].endswith("tri\ufffd.obj")
    png = os.path.join(folder, b"image\xfe.png")
    image = np.arange(4 * 3 * 3, dtype=np.uint8).reshape(4, 3, 3)
    mfr.write_png(png, image)
    assert (mfr.read_png(os.fsdecode(png))[..., :3] == image).all()
    assert mfr.metrics(png, os.fsdecode(png))["mse"] == 0
    model_path = os.path.join(folder, b"model\xfd.mfrnn")
    saved = mfr.save_model(model_path, mfr.builtin_model())
    assert mfr.load_model(os.fsdecode(model_path)).to_bytes() == saved.to_bytes()
    # a missing one: mfr.Error, the name's bytes shown as escapes (not a UnicodeDecodeError)
    with pytest.raises(mfr.Error) as e:
        mfr.load_scene(os.path.join(folder, b"missing\xff.obj"))
    assert "missing\\xff.obj" in str(e.value) and "\n" not in str(e.value)


if __name__ == "__main__":  # the child of test_wrong_arguments_name_the_function_and_the_parameter
    sweep(sys.argv[1], sys.argv[2])
