#!/usr/bin/env python3
"""Trains the deep k-buffer's 12-128-64-1 network in numpy alone, saves it as a .mfrnn model with
the mfr module, and renders with it: a model trained in Python runs in `dkb` unchanged.

    build/mfr dataset procedural:layers procedural:smoke --width 64 --height 64 --orbit 4 -o d.mfrds
    PYTHONPATH=build/python python3 examples/train_dkb.py d.mfrds -o numpy.mfrnn --epochs 20 \\
        --render procedural:hairball --budget 2MB --width 256 --height 256 --image hairball.png
    build/mfr render procedural:hairball -m dkb -M 2MB --model numpy.mfrnn -o same.png

The network and loss are those of `mfr train` (include/mfr/learn/mlp.hpp): ReLU, ReLU, sigmoid;
mean squared error plus L1 on the first and L2 on the second hidden layer's weights; He-uniform
initial weights. The optimiser is Adam by default (--optimizer sgd: the paper's plain mini-batch
SGD, learning rate 1e-3, batch 512). Validation is on held-out scenes (default: the last scene of
the datasets), as in `mfr train`. Prints one JSON summary line at the end (--summary: also to a
file).
"""

import argparse
import json
import os
import sys
import time

import numpy as np

import mfr

LAYERS = list(mfr.DKB_LAYERS)  # [12, 128, 64, 1]


def init_network(rng):
    """He-uniform weights (outputs, inputs), zero biases, as mfr train's makeMlp."""
    weights, biases = [], []
    for fan_in, fan_out in zip(LAYERS[:-1], LAYERS[1:]):
        limit = np.sqrt(6.0 / fan_in)
        weights.append(rng.uniform(-limit, limit, size=(fan_out, fan_in)).astype(np.float32))
        biases.append(np.zeros(fan_out, dtype=np.float32))
    return weights, biases


def forward(weights, biases, x):
    """Activations of every layer for samples x (N, 12): [x, h1, h2, y]."""
    acts = [x]
    for i, (w, b) in enumerate(zip(weights, biases)):
        z = acts[-1] @ w.T + b
        acts.append(np.maximum(z, 0) if i < len(weights) - 1 else 1 / (1 + np.exp(-z)))
    return acts


def mse(weights, biases, x, t):
    if len(x) == 0:
        return float("nan")
    return float(np.mean((forward(weights, biases, x)[-1][:, 0] - t) ** 2))


def gradients(weights, biases, x, t, l1, l2):
    """Gradients of mean (y - t)^2 + l1 sum|W1| + l2 sum W2^2 (mfr train's loss)."""
    acts = forward(weights, biases, x)
    y = acts[-1]
    delta = 2.0 * (y - t[:, None]) / len(x) * y * (1 - y)  # through the sigmoid
    gw, gb = [None] * len(weights), [None] * len(weights)
    for i in reversed(range(len(weights))):
        gw[i] = delta.T @ acts[i]
        gb[i] = delta.sum(axis=0)
        if i > 0:
            delta = (delta @ weights[i]) * (acts[i] > 0)  # through the ReLU
    gw[0] += l1 * np.sign(weights[0])
    gw[1] += 2 * l2 * weights[1]
    return gw, gb


def load(paths, validation_scenes):
    sets = [mfr.load_dataset(p) for p in paths]  # refuses stale datasets, as mfr train does
    order = []
    for d in sets:
        order += [s for s in d.scenes if s not in order]
    if validation_scenes == ["none"]:
        valid = set()
    elif validation_scenes:
        valid = set(validation_scenes)
        missing = valid - set(order)
        if missing:
            sys.exit(f"train_dkb: --validation-scene {sorted(missing)}: not in the datasets")
    else:
        valid = {order[-1]} if len(order) > 1 else set()
    xs, ts, is_valid = [], [], []
    for d in sets:
        names = np.array(d.scenes, dtype=object)[d.scene]
        xs.append(np.array(d.features))
        ts.append(np.array(d.targets))
        is_valid.append(np.isin(names, list(valid)))
    x, t, v = np.concatenate(xs), np.concatenate(ts), np.concatenate(is_valid)
    if not (~v).any():
        sys.exit("train_dkb: no training samples (every scene is held out)")
    datasets = [{"file": os.path.basename(p), "fnv1a64": d.file_hash} for p, d in zip(paths, sets)]
    return x[~v], t[~v], x[v], t[v], [s for s in order if s not in valid], sorted(valid), datasets


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("datasets", nargs="+", help=".mfrds files from `mfr dataset`")
    ap.add_argument("-o", "--out", required=True, help="the model to write (.mfrnn)")
    ap.add_argument("--epochs", type=int, default=20)
    ap.add_argument("--batch", type=int, default=512)
    ap.add_argument("--optimizer", choices=["adam", "sgd"], default="adam")
    ap.add_argument("--learning-rate", type=float, default=1e-3)
    ap.add_argument("--momentum", type=float, default=0.0, help="sgd only")
    ap.add_argument("--l1", type=float, default=1e-5, help="L1 weight, first hidden layer")
    ap.add_argument("--l2", type=float, default=1e-4, help="L2 weight, second hidden layer")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--validation-scene", action="append", default=[],
                    help="scene held out (repeatable; default the last scene; 'none')")
    ap.add_argument("--render", metavar="SCENE", help="render SCENE with dkb and the new model")
    ap.add_argument("--budget", default="2MB")
    ap.add_argument("--width", type=int, default=256)
    ap.add_argument("--height", type=int, default=256)
    ap.add_argument("--image", default="train_dkb.png", help="where --render writes its image")
    ap.add_argument("--summary", help="also write the JSON summary to this file")
    ap.add_argument("--quiet", action="store_true")
    a = ap.parse_args()
    if a.epochs < 1 or a.batch < 1 or not a.learning_rate > 0:
        sys.exit("train_dkb: --epochs, --batch and --learning-rate must be positive")

    x, t, vx, vt, train_scenes, valid_scenes, datasets = load(a.datasets, a.validation_scene)
    rng = np.random.default_rng(a.seed)
    weights, biases = init_network(rng)
    params = weights + biases
    state = [np.zeros_like(p) for p in params]  # momentum / Adam first moment
    second = [np.zeros_like(p) for p in params]  # Adam second moment
    step = 0
    log = []
    initial = mse(weights, biases, x, t)
    for epoch in range(1, a.epochs + 1):
        start = time.perf_counter()
        order = rng.permutation(len(x))
        for begin in range(0, len(x), a.batch):
            idx = order[begin:begin + a.batch]
            gw, gb = gradients(weights, biases, x[idx], t[idx], a.l1, a.l2)
            step += 1
            for p, g, m, v in zip(params, gw + gb, state, second):
                if a.optimizer == "sgd":
                    m *= a.momentum
                    m -= a.learning_rate * g
                    p += m
                else:
                    m *= 0.9
                    m += 0.1 * g
                    v *= 0.999
                    v += 0.001 * g * g
                    p -= (a.learning_rate * (m / (1 - 0.9 ** step))
                          / (np.sqrt(v / (1 - 0.999 ** step)) + 1e-8)).astype(np.float32)
        log.append({"epoch": epoch, "train_mse": mse(weights, biases, x, t),
                    "validation_mse": mse(weights, biases, vx, vt),
                    "seconds": time.perf_counter() - start})
        if not a.quiet:
            e = log[-1]
            print(f"epoch {epoch}: train {e['train_mse']:.5g}, validation "
                  f"{e['validation_mse']:.5g} ({e['seconds']:.2f} s)", file=sys.stderr)
    if not np.isfinite(log[-1]["train_mse"]):
        sys.exit("train_dkb: training diverged (non-finite loss); lower --learning-rate")

    final_valid = log[-1]["validation_mse"]
    model = mfr.save_model(a.out, weights, biases, metadata={
        "features": mfr.FEATURE_SET,
        "feature_normalisation": "include/mfr/method/dkb_features.hpp",
        "target": mfr.TARGET_SCALING,
        "layers": LAYERS,
        "activations": "relu, relu, sigmoid",
        "training": {
            "trainer": "examples/train_dkb.py (numpy " + np.__version__ + ")",
            "datasets": datasets, "train_scenes": train_scenes,
            "validation_scenes": valid_scenes, "train_samples": int(len(x)),
            "validation_samples": int(len(vx)), "epochs": a.epochs, "batch": a.batch,
            "optimizer": a.optimizer, "learning_rate": a.learning_rate,
            "momentum": a.momentum, "l1_first_hidden": a.l1, "l2_second_hidden": a.l2,
            "seed": a.seed, "final_train_mse": log[-1]["train_mse"],
            "final_validation_mse": final_valid if np.isfinite(final_valid) else None}})
    # the library runs the network numpy trained: its predictions are numpy's
    probe = x[:2048]
    library = model.predict(probe)[:, 0]
    ours = forward(weights, biases, probe)[-1][:, 0]
    max_difference = float(np.max(np.abs(library - ours))) if len(probe) else 0.0
    if max_difference > 1e-4:
        sys.exit(f"train_dkb: the library's predictions differ from numpy's by {max_difference}")

    summary = {"model": a.out, "train_samples": int(len(x)), "validation_samples": int(len(vx)),
               "initial_train_mse": initial, "final_train_mse": log[-1]["train_mse"],
               "final_validation_mse": final_valid if np.isfinite(final_valid) else None,
               "epochs": log, "library_vs_numpy_max_difference": max_difference}
    if a.render:
        r = mfr.render(a.render, method="dkb", budget=a.budget, width=a.width, height=a.height,
                       model=model)
        mfr.write_png(a.image, r.srgb)
        summary["render"] = {"scene": a.render, "image": a.image,
                             **{k: r.stats[k] for k in ("method", "budget_bytes", "bytes_used",
                                                        "fragments_captured", "fragments_lost",
                                                        "k_min", "k_max")}}
    text = json.dumps(summary)
    if a.summary:
        with open(a.summary, "w") as f:
            f.write(text + "\n")
    print(text)


if __name__ == "__main__":
    main()
