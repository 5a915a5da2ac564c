"""mfr: bounded-memory multi-fragment rendering and order-independent transparency.

The Python face of the C++ library (the extension module mfr._mfr):

    import mfr
    scene = mfr.load_scene("procedural:bottles")              # or a .gltf/.glb/.obj/.ply/.json
    r = mfr.render(scene, method="kplus-dynamic", budget="4MB", width=256, height=256)
    r.image, r.srgb, r.k_map, r.depth_complexity, r.importance  # numpy arrays
    r.stats["bytes_used"]                                      # keys of `mfr render --stats-json`
    mfr.write_png("out.png", r.srgb)
    m = mfr.metrics(reference_png_or_array, test_png_or_array)  # MSE, PSNR, FLIP (+ map)
    mfr.compare(scene, "out/compare", budgets=["2MB", "4MB"], methods=["fkb", "dkb"])
    data = mfr.load_dataset("train.mfrds")                      # features (N, 12), targets (N,)
    model = mfr.save_model("my.mfrnn", weights, biases)         # numpy weights -> dkb's model
    mfr.render(scene, method="dkb", budget="4MB", model=model)

Errors the library reports (missing files, unknown scenes or methods, budgets too small, options
that do not apply to a method, ...) raise mfr.Error (a RuntimeError) with the library's one-line
message, the same text `mfr` prints after "mfr: error: ". Arrays of the wrong shape raise
ValueError; arguments of the wrong type raise TypeError naming the parameter and the type
("importance['alpha']: expected a number, got str"). Rendering, loading and comparing release the
GIL. Returned arrays own the library's buffers (no copies); arrays that view a Scene, Model or
dataset are read-only.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import re
from typing import Any, Iterable, Sequence

import numpy as np

try:
    from . import _mfr
except ImportError as _error:  # most often: another Python than the one it was built for
    import sys as _sys
    try:
        from ._built_for import INTERPRETER as _BUILT_FOR, VERSION as _BUILT_VERSION
    except ImportError:
        raise _error from None
    _running = f"{_sys.version_info[0]}.{_sys.version_info[1]}"
    if _running == _BUILT_VERSION:
        raise
    raise ImportError(f"mfr: the extension module was built for Python {_BUILT_VERSION} "
                      f"({_BUILT_FOR}), not this Python {_running} ({_sys.executable}): run "
                      f"{_BUILT_FOR}, or rebuild with -DPython3_EXECUTABLE={_sys.executable}"
                      ) from None
from ._mfr import (  # noqa: F401  (re-exported)
    DKB_LAYERS,
    FEATURE_COUNT,
    FEATURE_SET,
    FLIP_DEFAULT_PPD,
    TARGET_SCALING,
    Error,
    Model,
    RenderResult,
    Scene,
    __version__,
)

__all__ = [
    "CompareResults", "DEFAULT_COMPARE_METHODS", "DKB_LAYERS", "FEATURE_COUNT", "FEATURE_SET", "FLIP_DEFAULT_PPD",
    "TARGET_SCALING", "Dataset", "Error", "Model", "RenderResult", "Scene", "builtin_model",
    "compare", "decode_srgb", "encode_srgb", "engine_names", "load_dataset", "load_model",
    "load_scene",
    "make_model", "metrics", "parse_bytes", "preset_names", "read_png", "render",
    "save_dataset", "save_model", "write_pfm", "write_png",
]

# --- arguments ---------------------------------------------------------------------------------
#
# Every public function is a Python function with its real signature (inspect.signature works; a
# missing or unknown argument is Python's own TypeError naming the function), and passes its
# arguments on unconverted: the extension converts each one and names the function and the
# parameter when it cannot ("render(): width: expected an integer, got str", "render(): seed:
# expected an integer in [0, 18446744073709551615], got -1"), never pybind11's "incompatible
# function arguments" signature dump or "Unable to cast Python instance". Paths are str, bytes or
# os.PathLike, passed to the file system as os.fsencode gives them.

_PREFIX = re.compile(r"^[\w.]+\(\): ")


@contextlib.contextmanager
def _as_function(name):
    """Argument errors of the functions called inside ("Model(): weights: ...") named after the
    public function `name` that was called ("make_model(): weights: ...")."""
    try:
        yield
    except (TypeError, ValueError, OverflowError) as e:
        text = str(e)
        if not _PREFIX.match(text):
            raise
        raise type(e)(_PREFIX.sub(name + "(): ", text, count=1)) from None


def _argument_error(function, kind, parameter, message):
    return kind(f"{function}(): {parameter}: {message}")


def _as_list(value, single):
    """A list argument: one `single` value as [value], an iterable (a generator, an array) as a
    list; anything else as it is, for the extension to refuse naming the parameter."""
    if isinstance(value, single):
        return [value]
    if isinstance(value, (str, bytes, dict)) or not isinstance(value, Iterable):
        return value
    return list(value)


def _path_text(value):
    """A path for a report's text: os.fspath of a path, anything else as it is."""
    return os.fspath(value) if isinstance(value, (str, bytes, os.PathLike)) else value


def _differs(value, default):
    try:
        return bool(value != default)
    except (TypeError, ValueError):  # e.g. a numpy array: no single truth value
        return True


def load_scene(source, *, seed=1, transmission_floor=0.1, alpha=None, background=None,
               memory_limit=None, allow_outside_references=False, gltf_scene=None) -> Scene:
    """Loads a scene: a .gltf/.glb, .obj, .ply or JSON scene file (a str, bytes or os.PathLike
    path), or "procedural:NAME[?k=v&...]". seed: procedural scenes' seed; transmission_floor:
    glass alpha floor; alpha: override every material's alpha (0..1); background: linear RGB;
    memory_limit: refuse scenes needing more (bytes or "8GB"; default 75% of the physical
    memory); allow_outside_references: let a scene file name files outside its folder (`mfr
    --allow-outside-references`); gltf_scene: which of a glTF file's scenes (`mfr --scene N`;
    default the file's own). Raises mfr.Error naming the input. Points and lines are not
    rendered: Scene.primitives_skipped counts them."""
    return _mfr.load_scene(source, seed=seed, transmission_floor=transmission_floor, alpha=alpha,
                           background=background, memory_limit=memory_limit,
                           allow_outside_references=allow_outside_references,
                           gltf_scene=gltf_scene)


def metrics(reference, test, ppd=FLIP_DEFAULT_PPD) -> dict:
    """Error of `test` against `reference`, as `mfr metrics --json` computes it: each a PNG path
    or an array (uint8 (h, w, 3|4) sRGB, or float (h, w, 3) linear, sRGB-encoded first). Returns
    a dict: width, height, mse_linear, mse_srgb, psnr_linear, psnr_srgb (inf when identical), mse
    and psnr (the linear ones), flip_mean, flip_median, flip_p95, flip_p99, flip_max,
    pixels_per_degree, and flip_map (LDR-FLIP per pixel, float32 (h, w) in [0, 1])."""
    return _mfr.metrics(reference, test, ppd)


def parse_bytes(text) -> int:
    """A size in bytes: "20MB" -> 20971520 (binary units, as the command line's --budget)."""
    return _mfr.parse_bytes(text)


def read_png(path) -> np.ndarray:
    """Reads a PNG as uint8 (height, width, 4) RGBA (sRGB colour)."""
    return _mfr.read_png(path)


def write_png(path, image) -> None:
    """Writes uint8 (h, w, 3|4) sRGB, or float (h, w, 3) linear RGB (sRGB-encoded as mfr render
    does), as a PNG. The path must end in .png (ValueError otherwise)."""
    _mfr.write_png(path, image)


def write_pfm(path, image) -> None:
    """Writes float (h, w, 3) linear RGB (r.image) as a Portable Float Map, as
    `mfr render -o NAME.pfm` does: float32, rows bottom to top, little-endian. The path must end
    in .pfm (ValueError otherwise)."""
    _mfr.write_pfm(path, image)


def encode_srgb(image) -> np.ndarray:
    """Linear float (h, w, 3) -> sRGB uint8 (h, w, 4), exactly as images are written."""
    return _mfr.encode_srgb(image)


def decode_srgb(image) -> np.ndarray:
    """sRGB uint8 (h, w, 3|4) -> linear float32 (h, w, 3)."""
    return _mfr.decode_srgb(image)


def engine_names() -> list:
    """The engines render and compare accept ("cpu", "gl")."""
    return _mfr.engine_names()


def preset_names() -> list:
    """The method presets (each bounded one also as NAME+occupancy)."""
    return _mfr.preset_names()


def builtin_model() -> Model:
    """The model dkb uses without model= (models/dkb-default.mfrnn, compiled into the
    library)."""
    return _mfr.builtin_model()


def _method(function, name, doc):
    function.__name__ = name
    function.__qualname__ = "Model." + name
    function.__doc__ = (doc or "").split("\n\n", 1)[-1]  # less pybind11's signature line
    return function


# Model's methods with their real signatures too (the extension's own raise the same named errors)
_model_predict, _model_save = Model.predict, Model.save
_model_to_bytes, _model_check_dkb, _model_load = Model.to_bytes, Model.check_dkb, Model.load
Model.predict = _method(lambda self, features: _model_predict(self, features), "predict",
                        _model_predict.__doc__)
Model.save = _method(lambda self, path: _model_save(self, path), "save", _model_save.__doc__)
Model.to_bytes = _method(lambda self: _model_to_bytes(self), "to_bytes", _model_to_bytes.__doc__)
Model.check_dkb = _method(lambda self: _model_check_dkb(self), "check_dkb",
                          _model_check_dkb.__doc__)
Model.load = staticmethod(_method(lambda path: _model_load(path), "load", _model_load.__doc__))
_model_init = Model.__init__
Model.__init__ = _method(lambda self, weights, biases, metadata:
                         _model_init(self, weights, biases, metadata), "__init__",
                         _model_init.__doc__)


#: The methods `mfr compare` runs when --methods is not given (the library's one list).
DEFAULT_COMPARE_METHODS = tuple(_mfr.DEFAULT_COMPARE_METHODS.split(","))


class CompareResults(dict):
    """results.json of a comparison as a dict, with .table(): one row per run."""

    def rows(self) -> list[dict]:
        """One dict per run (the ground truth first, then each budget's runs in order): the
        budget's budget_label and budget_bytes, then the run's keys of results.json (label,
        compositing, flip_mean, total_ms, bytes_used, error, ...), lists and dicts left out."""
        def flat(run, budget):
            row = {"budget_label": budget.get("budget_label", ""),
                   "budget_bytes": run.get("budget_bytes")}
            row.update({k: v for k, v in run.items() if not isinstance(v, (list, dict))})
            return row
        out = [flat(self["ground_truth"], {})]
        for budget in self.get("budgets", []):
            out.extend(flat(run, budget) for run in budget["methods"])
        return out

    def table(self):
        """The rows as a pandas DataFrame where pandas is installed, else the list of dicts."""
        try:
            import pandas
        except ImportError:
            return self.rows()
        return pandas.DataFrame(self.rows())


def render(scene, *, method="abuffer", budget=None, k=None, width=1024, height=1024, camera=None,
           view=None, orbit=0, orbit_view=None, zoom=1.0, composite=None, capture="tile",
           threads=0, seed=1, model=None, occupancy_d=None, importance=None, alpha=None,
           background=None, transmission_floor=0.1, shuffle_draw_order=None, gltf_scene=None,
           cull=None, blend=None, engine="cpu", gl_sync="auto", gl_raster="native",
           memory_limit=None, allow_outside_references=False, depth_complexity=True,
           max_peels=None, samples=1, sample_storage="pixel"):
    """Renders with one method, exactly as `mfr render` with the same options (the library checks
    both the same way: its errors name the Python argument where the CLI names its flag).

    scene: an mfr.Scene, or a source string ("procedural:NAME[?k=v&...]" or a file), loaded with
        `seed` and `transmission_floor` (alpha, background and shuffle_draw_order then change it;
        with an mfr.Scene they apply to a copy).
    method: a preset of mfr.preset_names() (optionally "NAME+occupancy").
    budget: the memory budget M: bytes (int), a size ("20MB", binary units) or a share of the
        exact A-buffer's node bytes ("25%", resolved on each view's count pass, as
        `mfr render --budget 25%`); bounded methods need it unless k is given.
    k: explicit k (fixed, counted and dynamic-k presets). composite: "kbuffer" or "hybrid"
        (default: the preset's own rule). capture: "tile" or "parallel". occupancy_d: buckets
        32*d of a "+occupancy" method. model: a .mfrnn path or an mfr.Model (dkb*; default the
        built-in model). importance: vkb's parameters as a dict (alpha, n_limit, periphery_d,
        fovea, noise, depth_term, periphery_term, fresnel_term, noise_term).
    camera: (eye xyz, target xyz[, up xyz[, fov degrees]]) as 6, 9 or 10 numbers or the CLI's
        text; view: index of a camera of the scene file; default: the scene's own camera, or one
        framing its bounds. zoom: moves the camera zoom times closer to its target. orbit: N views
        on a circle around the camera's target (a list of N results); orbit_view: only view I of
        them (one result; view I - 1 feeds vkb's previous-frame term, as in the full orbit).
    shuffle_draw_order: submit the triangles in this seed's random order. gltf_scene: which of a
        glTF file's scenes (`--scene N`; default the file's own). cull: the back faces culled,
        "auto" (as the file says: glTF materials with doubleSided false), "none" or "back" (every
        back face), as `mfr --cull`; None: the scene's own (Scene.cull, "auto" when loaded).
    blend: the materials' blend mode, as `mfr --blend`: "MODE" (every material) or
        "MATERIAL=MODE", or a list of them applied in order; MODE: "over", "premultiplied",
        "additive" or "multiply" (docs/METHODS.md, blend modes).
    engine: "cpu" or "gl" (mfr.engine_names()); gl_sync: the GL k-buffer's "auto", "lock" or
        "interlock"; gl_raster: the GL geometry passes, "native" (GL's own pipeline) or "exact"
        (the CPU engine's raster emulated: bit-identical to engine="cpu").
    threads: worker threads in [0, 1024] (0: all cores; the output does not depend on it).
        seed: procedural scenes and vkb's noise.
    memory_limit: refuse runs whose buffers need more (bytes or "8GB"; default 75% of the least
        of the physical memory, the address-space limit and the cgroup limit, as
        `mfr --memory-limit`). allow_outside_references: as `mfr --allow-outside-references`.
    depth_complexity: also count the fragments per pixel when the method does not.
    max_peels: depth peeling (peel, dual-peel): at most this many geometry passes, as
        `mfr render --max-peels` (the rest dropped, or with composite="hybrid" blended into a tail).
    samples: 1, 2, 4 or 8 samples per pixel at the standard Direct3D / Vulkan positions
        (antialiasing, both engines), as `mfr --samples`; sample_storage: "pixel" (one node per
        fragment with its coverage mask) or "sample" (nodes per sample), as `mfr
        --sample-storage` (docs/METHODS.md, multisampling). The arrays are per pixel: the image
        box-filtered, k_map and depth_complexity summed over the samples.

    Returns an mfr.RenderResult (a list of them with orbit and no orbit_view): image (float32
    (h, w, 3) linear RGB), srgb (uint8 (h, w, 4), the PNG's pixels), k_map (uint32 (h, w); None
    for methods without fragment slots, e.g. wboit), depth_complexity (uint32 (h, w) or None),
    importance (float32 (h, w) for vkb*/dkb*, else None) and stats (dict, the keys of
    --stats-json but 'image'). Raises mfr.Error with the library's message for bad input.
    """
    return _mfr.render(scene, method=method, budget=budget, k=k, width=width, height=height,
                       camera=camera, view=view, orbit=orbit, orbit_view=orbit_view, zoom=zoom,
                       composite=composite, capture=capture, threads=threads, seed=seed,
                       model=model, occupancy_d=occupancy_d, importance=importance, alpha=alpha,
                       background=background, transmission_floor=transmission_floor,
                       shuffle_draw_order=shuffle_draw_order, gltf_scene=gltf_scene, cull=cull,
                       blend=blend, engine=engine, gl_sync=gl_sync, gl_raster=gl_raster,
                       memory_limit=memory_limit,
                       allow_outside_references=allow_outside_references,
                       depth_complexity=depth_complexity, max_peels=max_peels, samples=samples,
                       sample_storage=sample_storage)


def compare(scene, out, budgets="auto", *, methods: Sequence[str] = DEFAULT_COMPARE_METHODS, width=1024,
            height=1024, camera=None, view=None, orbit=0, orbit_view=None, orbit_step=0.0,
            zoom=1.0,
            composite=None, capture="tile", threads=0, seed=1, model=None, ppd=FLIP_DEFAULT_PPD,
            alpha=None, background=None, transmission_floor=0.1, shuffle_draw_order=None,
            gltf_scene=None, cull=None, blend=None, engine="cpu", gl_sync="auto",
            gl_raster="native", memory_limit=None, allow_outside_references=False, samples=1,
            sample_storage="pixel", sample_counts=None, max_peels=None, repeat=3, warmup=1,
            truth_engine="") -> CompareResults:
    """Writes the folder `mfr compare --out OUT` writes for the same options and returns its
    results.json as a dict.

    The ground truth (exact A-buffer) once, then every method at every budget, measured against
    it: OUT/ground_truth.png, ground_truth_depth_complexity.png, METHOD_BUDGET.png, _flip.png,
    _kmap.png, (_importance.png), results.json, results.csv and report.html (its command line
    is this call). budgets: one budget or a list (bytes, "20MB" sizes or "25%" shares of the
    A-buffer); methods: presets; composite: "kbuffer" / "hybrid" for every method (default each
    preset's own rule); model: the dkb* network (path or mfr.Model); ppd: FLIP's pixels per
    degree. orbit=N: the temporal comparison of `mfr compare --orbit N` (every frame in
    OUT/frame_NNN, the flicker of each method along the path in results.json and report.html;
    orbit_step: degrees between frames, default 360/N); with orbit_view=I only view I of the N
    is compared. scene, camera, view, zoom, width, height, threads, seed, alpha, background,
    transmission_floor, shuffle_draw_order, gltf_scene, cull, blend, engine, gl_sync, gl_raster,
    memory_limit, allow_outside_references, samples, sample_storage: as in mfr.render (the
    ground truth of a multisampled comparison is the per-sample A-buffer, box-filtered).
    sample_counts: sample counts (e.g. [1, 4, 8]) to run the comparison at too, each against its
    own ground truth, as `mfr compare --sample-counts` (results.json "sample_counts", the
    report's error-vs-bytes-per-pixel figure per count). composite: a rule, "kbuffer,hybrid" or
    a list; default both, every method that takes a rule running under each (labels
    "fkb-kbuffer", "fkb-hybrid"). max_peels: --max-peels of peel and dual-peel. repeat, warmup:
    timed and untimed renders per run (total_ms is the median, total_ms_min/max the spread).
    truth_engine: the ground truth's engine ("" the comparison's, with the CPU engine taking
    over when a GPU refuses the A-buffer). budgets="auto": log-spaced from the methods' smallest
    budget to the A-buffer's. A method that fails at a budget is recorded with its error; bad
    input raises mfr.Error. Returns results.json as a CompareResults dict; .table() gives one
    row per run (a pandas DataFrame where pandas is installed).
    """
    budgets = _as_list(budgets, (str, int))
    if isinstance(methods, str):
        methods = [m.strip() for m in methods.split(",")]
    methods = _as_list(methods, ())
    call = [repr(scene.name if isinstance(scene, Scene) else _path_text(scene)),
            repr(_path_text(out)), f"budgets={budgets!r}", f"methods={methods!r}",
            f"width={width!r}", f"height={height!r}"]
    for name, value, default in (("camera", camera, None), ("view", view, None),
                                 ("orbit", orbit, 0), ("orbit_view", orbit_view, None),
                                 ("orbit_step", orbit_step, 0.0),
                                 ("zoom", zoom, 1.0), ("composite", composite, None),
                                 ("capture", capture, "tile"), ("threads", threads, 0),
                                 ("seed", seed, 1), ("ppd", ppd, FLIP_DEFAULT_PPD),
                                 ("alpha", alpha, None), ("background", background, None),
                                 ("transmission_floor", transmission_floor, 0.1),
                                 ("shuffle_draw_order", shuffle_draw_order, None),
                                 ("gltf_scene", gltf_scene, None), ("cull", cull, None),
                                 ("blend", blend, None),
                                 ("engine", engine, "cpu"), ("gl_sync", gl_sync, "auto"),
                                 ("gl_raster", gl_raster, "native"),
                                 ("memory_limit", memory_limit, None),
                                 ("allow_outside_references", allow_outside_references, False),
                                 ("samples", samples, 1), ("sample_storage", sample_storage,
                                                           "pixel"),
                                 ("sample_counts", sample_counts, None),
                                 ("max_peels", max_peels, None), ("repeat", repeat, 3),
                                 ("warmup", warmup, 1), ("truth_engine", truth_engine, "")):
        if _differs(value, default):
            call.append(f"{name}={value!r}")
    if model is not None:
        call.append("model=<mfr.Model>" if isinstance(model, Model) else
                    f"model={_path_text(model)!r}")
    return CompareResults(_mfr._compare(scene, out, budgets=budgets, methods=methods, width=width,
                         height=height, camera=camera, view=view, orbit=orbit,
                         orbit_view=orbit_view, orbit_step=orbit_step, zoom=zoom,
                         composite=composite, capture=capture, threads=threads, seed=seed,
                         model=model, ppd=ppd, alpha=alpha, background=background,
                         transmission_floor=transmission_floor,
                         shuffle_draw_order=shuffle_draw_order, gltf_scene=gltf_scene, cull=cull,
                         blend=blend, engine=engine, gl_sync=gl_sync, gl_raster=gl_raster,
                         memory_limit=memory_limit,
                         allow_outside_references=allow_outside_references, samples=samples,
                         sample_storage=sample_storage, sample_counts=sample_counts,
                         max_peels=max_peels, repeat=repeat, warmup=warmup,
                         truth_engine=truth_engine,
                         command_line="mfr.compare(" + ", ".join(call) + ")"))


# --- the deep k-buffer's models ----------------------------------------------------------------

def _default_metadata(sizes: Sequence[int]) -> dict:
    return {
        "features": FEATURE_SET,
        "feature_normalisation": "include/mfr/method/dkb_features.hpp",
        "target": TARGET_SCALING,
        "layers": list(sizes),
        "activations": ", ".join(["relu"] * (len(sizes) - 2) + ["sigmoid"]),
        "written_by": f"mfr {__version__} (Python)",
    }


def make_model(weights: Sequence[Any], biases: Sequence[Any], metadata=None) -> Model:
    """An mfr.Model from numpy arrays: weights[l] of shape (outputs, inputs), biases[l] of shape
    (outputs,), for y = relu(W x + b) on hidden layers and sigmoid(W x + b) at the output (the
    network dkb runs; PyTorch's nn.Linear.weight has this layout). Values are stored as float32.

    metadata: None (the deep k-buffer's declarations: features, target, layers, activations), a
    dict (FEATURE_SET and TARGET_SCALING are added as "features" and "target" when missing, so
    dkb accepts the model) or a str written verbatim (JSON text).
    """
    with _as_function("make_model"):
        return _make_model("make_model", weights, biases, metadata)


def _sizes(weights) -> list:
    """The layer sizes the weight arrays declare, for the default metadata ([] when they do not
    have the shapes of a network: Model() then says what is wrong, naming the argument)."""
    try:
        shapes = [np.shape(w) for w in weights]
        return [int(shapes[0][-1])] + [int(shape[0]) for shape in shapes]
    except (TypeError, ValueError, IndexError):
        return []


def _make_model(function, weights, biases, metadata) -> Model:
    weights, biases = _as_list(weights, ()), _as_list(biases, ())
    if metadata is None or isinstance(metadata, dict):
        meta = _default_metadata(_sizes(weights)) if metadata is None else dict(metadata)
        meta.setdefault("features", FEATURE_SET)
        meta.setdefault("target", TARGET_SCALING)
        try:
            metadata = json.dumps(meta, indent=2, allow_nan=False)
        except (TypeError, ValueError) as e:
            raise _argument_error(function, type(e), "metadata", f"not JSON: {e}") from None
    elif not isinstance(metadata, str):
        raise _argument_error(function, TypeError, "metadata",
                              f"expected None, a dict or a JSON str, got {type(metadata).__name__}")
    return Model(weights, biases, metadata)


def save_model(path, weights, biases=None, metadata=None) -> Model:
    """Writes a .mfrnn model (include/mfr/learn/model_file.hpp) that `mfr render -m dkb --model`
    and mfr.render(method="dkb", model=...) use unchanged. `weights` is a list of weight arrays
    (see make_model) with `biases`, or an mfr.Model. Returns the mfr.Model written."""
    with _as_function("save_model"):
        model = (weights if isinstance(weights, Model) else
                 _make_model("save_model", weights, biases, metadata))
        model.save(path)
    return model


def load_model(path) -> Model:
    """Reads a .mfrnn model; model.weights / model.biases are read-only float32 arrays
    (np.array(w) copies them for training), model.metadata the JSON text. Raises mfr.Error
    naming the file for a missing, truncated or malformed file."""
    with _as_function("load_model"):
        return Model.load(path)


# --- datasets ----------------------------------------------------------------------------------

@dataclasses.dataclass
class Dataset:
    """A .mfrds training set (include/mfr/learn/dataset.hpp) as numpy arrays, one row per sample.

    features: float32 (N, 12), the deep k-buffer's inputs (include/mfr/method/dkb_features.hpp);
    targets: float32 (N,), t(p) = K_M(p) / max K_M; scene, view, budget_step, pixel: uint32 (N,),
    scene indexing `scenes`. Loaded arrays are read-only views of one buffer (np.array copies).
    """

    scenes: list
    features: np.ndarray
    targets: np.ndarray
    scene: np.ndarray
    view: np.ndarray
    budget_step: np.ndarray
    pixel: np.ndarray
    metadata: Any = None  # dict when the file's metadata is JSON, else its text
    file_hash: str = ""  # FNV-1a 64 of the file's bytes (what mfr train records)
    metadata_text: str = ""  # the metadata exactly as in the file

    def __len__(self) -> int:
        return int(self.targets.shape[0])


def load_dataset(path, *, check: bool = True) -> Dataset:
    """Reads a .mfrds dataset written by `mfr dataset` (or save_dataset). check: refuse, as
    `mfr train` does, a dataset whose metadata declares another feature set or target than this
    build's (mfr.Error). Raises mfr.Error naming the file for a missing or malformed file."""
    d = _mfr._load_dataset(path, check)
    try:
        metadata = json.loads(d["metadata"]) if d["metadata"] else None
    except ValueError:
        metadata = d["metadata"]
    return Dataset(scenes=list(d["scenes"]), features=d["features"], targets=d["targets"],
                   scene=d["scene"], view=d["view"], budget_step=d["budget_step"],
                   pixel=d["pixel"], metadata=metadata, file_hash=d["file_hash"],
                   metadata_text=d["metadata"])


def save_dataset(path, features, targets=None, scenes: Iterable[str] = ("python",), *, scene=None,
                 view=None, budget_step=None, pixel=None, metadata=None) -> None:
    """Writes a .mfrds dataset: features (N, 12), targets (N,), scene names, and per-sample
    scene / view / budget_step / pixel indices (default 0). metadata: None (this build's feature
    set and target), a dict (JSON) or a str. A Dataset can be passed as `features` alone (its
    metadata text is kept, so a loaded dataset is written back byte for byte)."""
    if isinstance(features, Dataset):
        data = features
        features, targets, scenes = data.features, data.targets, data.scenes
        scene, view, budget_step, pixel = data.scene, data.view, data.budget_step, data.pixel
        if metadata is None:  # as read: the same bytes are written back
            metadata = data.metadata_text if data.metadata_text else data.metadata
    elif targets is None:
        raise _argument_error("save_dataset", TypeError, "targets",
                              "required with a features array")
    if metadata is None:
        metadata = {"features": FEATURE_SET, "target": TARGET_SCALING,
                    "written_by": f"mfr {__version__} (Python)"}
    if isinstance(metadata, dict):
        try:
            metadata = json.dumps(metadata, allow_nan=False)
        except (TypeError, ValueError) as e:
            raise _argument_error("save_dataset", type(e), "metadata", f"not JSON: {e}") from None
    _mfr._save_dataset(path, features, targets, _as_list(scenes, ()), scene, view, budget_step,
                       pixel, metadata)
