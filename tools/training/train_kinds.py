"""Trains the kind classifier (docs/kind-classifier.md): a linear head over an ImageNet MobileNetV2's pooled
features, on the renders of g2p_make_kind_dataset, then writes it as one ONNX network with its labels and card.

    /usr/bin/python3 -m tools.training.train_kinds DATASET MNV2_DIR OUT [--features LAYER,...]
        [--min-models 2] [--weight-decay 1e-3] [--epochs 300] [--folds 5]

DATASET: g2p_make_kind_dataset's folder (models.csv, views.csv, images/). MNV2_DIR: the MobileNetV2 of the npm
package nsfwjs 4.4.0 unpacked by unpack_nsfwjs.js (mobilenet_v2.json, .bin). The backbone stays frozen; its
features are computed once and cached in DATASET/features-LAYERS.npy.

The head is multinomial logistic regression over the kinds with at least --min-models training models, plus a
leading "other" class for the models of the kinds below that (the classifier identifier reads a network with one score more
than labels as having a leading background class). Views are fused as the identifier fuses them: the mean of the
per-view probabilities. A model's loss weight is 1 / (its kind's model count)^--balance (0.5), so that the 21 chairs do not
drown the single kinds. The temperature that calibrates the fused confidence is fitted on out-of-fold
predictions of the training models (--folds 3, split by model), and divides the head's weights in the export, so
the shipped network's probabilities are the calibrated ones. Validation (the split g2p_make_kind_dataset marked
from data/mass-ranges/val.json) is scored and reported, never trained or calibrated on.

With shape cues (DATASET/cues.csv, g2p::shape_cues() of each copy's mesh; --shape-hidden 0 leaves them out), a
second head, a small MLP over the standardised cues, gives each class a log-probability from the shape alone;
the two join as log p(views) + w log p(shape), renormalised, with w fitted like the temperature on out-of-fold
predictions. The shape head ships in the card (its weights as JSON), for the classifier identifier to run on
the mesh.

OUT gets g2p-kinds.onnx, g2p-kinds.txt (the kinds in output order after "other"), g2p-kinds.json (the card:
input, normalisation, data, per-kind counts, scores) and report.json (reliability diagram, per-model results).
"""
import argparse
import csv
import json
import math
import os
import re
import sys
from collections import Counter, defaultdict

import numpy as np
import torch
import torch.nn as nn
import torch.nn.functional as F

if __name__ == "__main__" and not __package__:  # run as a script: import the package as python3 -m does
    sys.path[0] = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    __package__ = "tools.training"

from .keras_layers import LayersModel  # noqa: E402

OTHER = "other"


class Backbone(nn.Module):
    """The MobileNetV2's feature maps at LAYERS, each averaged over the image and joined."""

    def __init__(self, folder, layers):
        super().__init__()
        self.net = LayersModel(folder, "mobilenet_v2.json", layers)

    def forward(self, x):
        # Global average pooling and flatten, as ONNX GlobalAveragePool (OpenCV 4.6 misreads a ReduceMean here).
        return torch.cat([torch.flatten(F.adaptive_avg_pool2d(f, 1), 1) for f in self.net(x)], dim=1)


class KindClassifier(nn.Module):
    """The shipped network: pixels normalised to [-1, 1] (NCHW, RGB) in, per-kind probabilities out."""

    def __init__(self, backbone, head, temperature):
        super().__init__()
        self.backbone, self.head, self.temperature = backbone, head, temperature

    def forward(self, x):
        return F.softmax(self.head(self.backbone(x)) / self.temperature, dim=1)


def read_csv(path):
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def export_onnx(net, path):
    # Opset 10: Pad takes its pads as an attribute, which OpenCV 4.6's importer reads (opset 11's input it does not).
    torch.onnx.export(net, torch.zeros(1, 3, 224, 224), path, input_names=["pixels"], output_names=["output"],
                      opset_version=10, do_constant_folding=True)


def features(dataset, views, backbone, tag):
    """The backbone's features of every view, computed by OpenCV's dnn on the exported backbone: the same
    inference the classifier identifier runs, and ten times as fast as torch here. Cached."""
    import cv2  # python3-opencv

    cache = os.path.join(dataset, f"features-{tag}.npy")
    if os.path.exists(cache):
        x = np.load(cache)
        if len(x) == len(views):
            return x
    onnx_path = os.path.join(dataset, f"backbone-{tag}.onnx")
    export_onnx(backbone, onnx_path)
    net = cv2.dnn.readNetFromONNX(onnx_path)
    out, batch = [], 32
    for i in range(0, len(views), batch):
        images = [cv2.cvtColor(cv2.imread(os.path.join(dataset, "images", v["image"])), cv2.COLOR_BGR2RGB)
                  for v in views[i:i + batch]]
        # (pixel - 127.5) / 127.5, RGB: the classifier identifier's normalization=minus-one-to-one.
        net.setInput(cv2.dnn.blobFromImages(images, 1 / 127.5, (224, 224), (127.5, 127.5, 127.5), False, False))
        out.append(net.forward().reshape(len(images), -1))
        if (i // batch) % 100 == 0:
            print(f"features: {i + len(images)}/{len(views)}", file=sys.stderr, flush=True)
    x = np.concatenate(out).astype(np.float32)
    np.save(cache, x)
    return x


def train_head(x, y, w, classes, weight_decay, epochs, seed=0):
    """Weighted multinomial logistic regression with an L2 penalty on the weights, by full-batch L-BFGS (the
    problem is convex: `epochs` iterations reach its optimum to plotting accuracy)."""
    torch.manual_seed(seed)
    head = nn.Linear(x.shape[1], classes)
    xt, yt, wt = torch.from_numpy(x), torch.from_numpy(y), torch.from_numpy(w / w.sum())
    opt = torch.optim.LBFGS(head.parameters(), lr=1, max_iter=epochs, history_size=20,
                            line_search_fn="strong_wolfe", tolerance_grad=1e-6, tolerance_change=1e-9)

    def closure():
        opt.zero_grad()
        loss = (F.cross_entropy(head(xt), yt, reduction="none") * wt).sum() + weight_decay * head.weight.pow(2).sum()
        loss.backward()
        return loss

    opt.step(closure)
    return head


def fused(head, x, groups, temperature=1.0):
    """{model: mean per-view probabilities} for the views of each model (groups: model -> view rows)."""
    with torch.no_grad():
        p = F.softmax(head(torch.from_numpy(x)) / temperature, dim=1).numpy()
    return {m: p[rows].mean(axis=0) for m, rows in groups.items()}


def fuse(z, temperature, fusion):
    """A model's class probabilities from its views' logits z (views x classes): the mean of the per-view
    softmaxes ("mean"), or the softmax of the mean logits ("geometric": the renormalised geometric mean of the
    per-view probabilities), at `temperature`."""
    if fusion == "geometric":
        m = z.mean(axis=0) / temperature
        p = np.exp(m - m.max())
        return p / p.sum()
    p = np.exp((z - z.max(axis=1, keepdims=True)) / temperature)
    return (p / p.sum(axis=1, keepdims=True)).mean(axis=0)


def fit_temperature(logits_by_model, truth, fusion):
    """The temperature that minimises the negative log-likelihood of each model's true class under the fusion,
    by golden-section search on log T."""
    def nll(t):
        return -sum(math.log(max(fuse(z, t, fusion)[truth[m]], 1e-12)) for m, z in logits_by_model.items())
    a, b = math.log(0.05), math.log(20.0)
    g = (math.sqrt(5) - 1) / 2
    c, d = b - g * (b - a), a + g * (b - a)
    for _ in range(60):
        if nll(math.exp(c)) < nll(math.exp(d)):
            b = d
        else:
            a = c
        c, d = b - g * (b - a), a + g * (b - a)
    return math.exp((a + b) / 2)


def read_cues(path):
    """{model: {copy: cue vector}} and the cue names, from g2p_make_kind_dataset's cues.csv."""
    rows = read_csv(path)
    names = [k for k in rows[0] if k not in ("model", "copy")] if rows else []
    out = defaultdict(dict)
    for r in rows:
        out[r["model"]][int(r["copy"])] = np.array([float(r[k]) for k in names], dtype=np.float32)
    return out, names


class ShapeHead(nn.Module):
    """Class logits from standardised shape cues: one tanh layer of `hidden` units (0: linear)."""

    def __init__(self, cues, hidden, classes):
        super().__init__()
        self.layers = nn.ModuleList([nn.Linear(cues, hidden), nn.Linear(hidden, classes)] if hidden
                                    else [nn.Linear(cues, classes)])

    def forward(self, z):
        for i, layer in enumerate(self.layers):
            z = layer(z)
            if i + 1 < len(self.layers):
                z = torch.tanh(z)
        return z


def train_shape_head(z, y, w, classes, hidden, weight_decay, iterations=300, seed=0):
    """The shape head by full-batch L-BFGS on the weighted cross-entropy with an L2 penalty on the weights."""
    torch.manual_seed(seed)
    head = ShapeHead(z.shape[1], hidden, classes)
    zt, yt, wt = torch.from_numpy(z), torch.from_numpy(y), torch.from_numpy(w / w.sum())
    opt = torch.optim.LBFGS(head.parameters(), lr=1, max_iter=iterations, history_size=20,
                            line_search_fn="strong_wolfe", tolerance_grad=1e-6, tolerance_change=1e-9)

    def closure():
        opt.zero_grad()
        loss = (F.cross_entropy(head(zt), yt, reduction="none") * wt).sum() + \
            weight_decay * sum(layer.weight.pow(2).sum() for layer in head.layers)
        loss.backward()
        return loss

    opt.step(closure)
    return head


def shape_logp(head, z):
    with torch.no_grad():
        return F.log_softmax(head(torch.from_numpy(z[None].astype(np.float32))), dim=1).numpy()[0]


def join(p_views, logp_shape, w):
    """Views' probabilities and the shape's log-probabilities joined: p(views) * p(shape)^w, renormalised."""
    if logp_shape is None or w == 0:
        return p_views
    lp = np.log(np.maximum(p_views, 1e-12)) + w * logp_shape
    q = np.exp(lp - lp.max())
    return q / q.sum()


def fit_shape_weight(p_views, logp_shape, truth):
    """The w in [0, 2] that minimises the out-of-fold negative log-likelihood of the joined probabilities."""
    def nll(w):
        return -sum(math.log(max(join(p_views[m], logp_shape[m], w)[truth[m]], 1e-12)) for m in truth)
    a, b = 0.0, 2.0
    g = (math.sqrt(5) - 1) / 2
    c, d = b - g * (b - a), a + g * (b - a)
    for _ in range(40):
        if nll(c) < nll(d):
            b = d
        else:
            a = c
        c, d = b - g * (b - a), a + g * (b - a)
    return (a + b) / 2


class Part(nn.Module):
    """The backbone up to one layer, unpooled (its values are cached for fine-tuning the layers after it)."""

    def __init__(self, folder, layer):
        super().__init__()
        self.net = LayersModel(folder, "mobilenet_v2.json", [layer])

    def forward(self, x):
        return self.net(x)[0]


def layer_values(dataset, views, folder, layer):
    """Every view's value at `layer` (NCHW, float16), computed by OpenCV's dnn on the backbone exported up to it.
    Cached in DATASET/values-LAYER.npy."""
    import cv2  # python3-opencv

    cache = os.path.join(dataset, f"values-{layer}.npy")
    if os.path.exists(cache):
        v = np.load(cache, mmap_mode="r")
        if len(v) == len(views):
            return v
    onnx_path = os.path.join(dataset, f"part-{layer}.onnx")
    export_onnx(Part(folder, layer).eval(), onnx_path)
    net = cv2.dnn.readNetFromONNX(onnx_path)
    out, batch = None, 32
    for i in range(0, len(views), batch):
        images = [cv2.cvtColor(cv2.imread(os.path.join(dataset, "images", v["image"])), cv2.COLOR_BGR2RGB)
                  for v in views[i:i + batch]]
        net.setInput(cv2.dnn.blobFromImages(images, 1 / 127.5, (224, 224), (127.5, 127.5, 127.5), False, False))
        y = net.forward()
        if out is None:
            out = np.zeros((len(views),) + y.shape[1:], np.float16)
        out[i:i + len(images)] = y
        if (i // batch) % 100 == 0:
            print(f"{layer}: {i + len(images)}/{len(views)}", file=sys.stderr, flush=True)
    np.save(cache, out)
    return np.load(cache, mmap_mode="r")


def tuned_features(net, start, values, rows, batch=256):
    """The pooled out_relu features of the views `rows` from their cached values at `start`."""
    out = []
    with torch.no_grad():
        for i in range(0, len(rows), batch):
            v = torch.from_numpy(np.asarray(values[np.sort(rows[i:i + batch])], dtype=np.float32))
            order = np.argsort(np.argsort(rows[i:i + batch]))  # back to the rows' order
            out.append(torch.flatten(F.adaptive_avg_pool2d(net.forward_from(start, v)[0], 1), 1)[order].numpy())
    return np.concatenate(out) if out else np.zeros((0, 1280), np.float32)


def fine_tune(net, start, values, rows, y, w, head, epochs, lr, anchor, weight_decay, seed=0):
    """Fine-tunes the layers after `start` and the head together: Adam on minibatches of 64 views, the weighted
    cross-entropy, the head's L2 penalty, and an L2 pull of the tuned layers towards their pretrained weights
    (`anchor`; L2-SP, Li et al. 2018), batch normalisation kept at its moving statistics. The views' values at
    `start` are cached: the layers before it never run."""
    tuned = net.downstream_parameters(start)
    pretrained = {k: p.detach().clone() for k, p in tuned.items()}
    for p in tuned.values():
        p.requires_grad_(True)
    opt = torch.optim.Adam([{"params": list(tuned.values()), "lr": lr}, {"params": head.parameters(), "lr": 3 * lr}])
    rng = np.random.default_rng(seed)
    total = float(w.sum())
    for epoch in range(epochs):
        order = rng.permutation(len(rows))
        for i in range(0, len(order), 64):
            b = order[i:i + 64]
            b = b[np.argsort(rows[b])]  # the cache read in file order
            v = torch.from_numpy(np.asarray(values[rows[b]], dtype=np.float32))
            logits = head(torch.flatten(F.adaptive_avg_pool2d(net.forward_from(start, v)[0], 1), 1))
            loss = (F.cross_entropy(logits, torch.from_numpy(y[b]), reduction="none") *
                    torch.from_numpy(w[b])).sum() * (len(order) / len(b) / total)
            loss = loss + weight_decay * head.weight.pow(2).sum() + \
                anchor * sum((p - pretrained[k]).pow(2).sum() for k, p in tuned.items())
            opt.zero_grad()
            loss.backward()
            opt.step()
        print(f"fine-tune: epoch {epoch + 1}/{epochs}, loss {float(loss):.3f}", file=sys.stderr, flush=True)
    for p in tuned.values():
        p.requires_grad_(False)
    return head


def logit(c):
    c = min(max(c, 1e-6), 1 - 1e-6)
    return math.log(c / (1 - c))


def fit_platt(confidence, right):
    """(a, b) of calibrated = sigmoid(a * logit(c) + b), fitted by logistic regression of whether the top kind
    was right on its fused confidence (Platt 1999)."""
    x = torch.tensor([logit(c) for c in confidence], dtype=torch.float64)
    y = torch.tensor([float(r) for r in right], dtype=torch.float64)
    ab = torch.tensor([1.0, 0.0], dtype=torch.float64, requires_grad=True)
    opt = torch.optim.LBFGS([ab], lr=1, max_iter=200, line_search_fn="strong_wolfe")

    def closure():
        opt.zero_grad()
        loss = F.binary_cross_entropy_with_logits(ab[0] * x + ab[1], y)
        loss.backward()
        return loss

    opt.step(closure)
    return float(ab[0]), float(ab[1])


def platt(c, ab):
    return 1 / (1 + math.exp(-(ab[0] * logit(c) + ab[1])))


def reliability(confidence, right, bins=10):
    rows = []
    for i in range(bins):
        lo, hi = i / bins, (i + 1) / bins
        idx = [k for k, c in enumerate(confidence) if lo <= c < hi or (i == bins - 1 and c == 1.0)]
        if idx:
            rows.append({"bin": [lo, hi], "models": len(idx), "mean_confidence": float(np.mean([confidence[k] for k in idx])),
                         "right": float(np.mean([right[k] for k in idx]))})
    n = len(confidence)
    ece = sum(r["models"] / n * abs(r["mean_confidence"] - r["right"]) for r in rows) if n else 0.0
    return rows, ece


def card_text(card):
    """The card as indented JSON with each list of numbers on one line, the shape head's float32 weights written
    to 9 significant digits (exactly)."""
    def tidy(v):
        if isinstance(v, dict):
            return {k: tidy(x) for k, x in v.items()}
        if isinstance(v, list):
            return [tidy(x) for x in v]
        return float(f"{v:.9g}") if isinstance(v, float) else v
    text = json.dumps(tidy(card), indent=1)
    return re.sub(r"\[\s*(-?[0-9][-0-9.e+,\s]*?)\s*\]",
                  lambda m: "[" + ", ".join(x.strip() for x in m.group(1).split(",")) + "]", text) + "\n"


def shape_card(head, names, mean, scale, weight):
    """The shape head as the classifier identifier reads it (classifier_identifier.cpp)."""
    return {
        "cues": names, "mean": [float(v) for v in mean], "scale": [float(v) for v in scale],
        "layers": [{"weights": layer.weight.detach().double().numpy().tolist(),
                    "bias": layer.bias.detach().double().numpy().tolist(),
                    "activation": "tanh" if i + 1 < len(head.layers) else "none"}
                   for i, layer in enumerate(head.layers)],
        "weight": weight,
        "about": "g2p::shape_cues() of the mesh, standardised ((cue - mean) / scale), through the layers (weights: "
                 "outputs x inputs) give a log-probability per class (softmax); the kind's probability is "
                 "p(views) * p(shape)^weight, renormalised, before the calibration",
    }


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dataset")
    ap.add_argument("mnv2")
    ap.add_argument("out")
    ap.add_argument("--features", default="out_relu", help="MobileNetV2 layers pooled into features (default out_relu)")
    ap.add_argument("--min-models", type=int, default=2, help="least training models for a kind to be a class")
    ap.add_argument("--weight-decay", type=float, default=1e-4)
    ap.add_argument("--epochs", type=int, default=100, help="L-BFGS iterations")
    ap.add_argument("--folds", type=int, default=3)
    ap.add_argument("--fusion", choices=["mean", "geometric"], default="mean",
                    help="how views are joined: the mean of their probabilities (default, as the classifier "
                         "identifier joins them), or their geometric mean")
    ap.add_argument("--balance", type=float, default=0.5,
                    help="a model's loss weight is 1 / (its kind's model count)^BALANCE (default 0.5)")
    ap.add_argument("--cues", default=None, help="shape cues (default DATASET/cues.csv)")
    ap.add_argument("--shape-hidden", type=int, default=32,
                    help="tanh units of the shape head (default 32; 0 = linear; -1 = no shape head)")
    ap.add_argument("--shape-weight-decay", type=float, default=1e-3)
    ap.add_argument("--fine-tune", default="", metavar="LAYER",
                    help="also train the backbone's layers after LAYER (e.g. block_15_add: block_16 and Conv_1), "
                         "from each view's cached value at LAYER; default: the backbone stays frozen")
    ap.add_argument("--fine-tune-epochs", type=int, default=4)
    ap.add_argument("--fine-tune-lr", type=float, default=1e-4)
    ap.add_argument("--fine-tune-anchor", type=float, default=1e-3,
                    help="L2 pull of the tuned layers towards their pretrained weights")
    ap.add_argument("--no-export", action="store_true", help="score only (for choosing)")
    a = ap.parse_args(argv)
    torch.set_num_threads(max(1, os.cpu_count() or 1))

    models = {m["model"]: m for m in read_csv(os.path.join(a.dataset, "models.csv"))}
    views = read_csv(os.path.join(a.dataset, "views.csv"))
    layers = a.features.split(",")
    backbone = Backbone(a.mnv2, layers).eval()
    x = features(a.dataset, views, backbone, "+".join(layers))

    train_models = [m for m in sorted({v["model"] for v in views}) if models[m]["split"] == "train"]
    counts = Counter(models[m]["kind"] or OTHER for m in train_models)
    kinds = sorted(k for k, n in counts.items() if k != OTHER and n >= a.min_models)
    classes = [OTHER] + kinds
    index = {k: i for i, k in enumerate(classes)}

    def label(m):
        return index.get(models[m]["kind"] or OTHER, 0)

    rows_of = defaultdict(list)
    for i, v in enumerate(views):
        rows_of[v["model"]].append(i)
    weight_of = {k: 1.0 / n ** a.balance for k, n in counts.items()}

    if a.fine_tune and layers != ["out_relu"]:
        sys.exit("train_kinds: --fine-tune needs --features out_relu")
    values = layer_values(a.dataset, views, a.mnv2, a.fine_tune) if a.fine_tune else None
    pretrained = {k: p.detach().clone() for k, p in backbone.net.params.items()}

    def trained(ms):
        """The head (and with --fine-tune the backbone's last layers, from their pretrained weights) trained on
        the views of models `ms`; and the pooled features of any views under it."""
        head = train_head(*arrays(ms), len(classes), a.weight_decay, a.epochs)
        if not a.fine_tune:
            return head, lambda rows: x[rows]
        with torch.no_grad():
            for k, p in backbone.net.params.items():
                p.copy_(pretrained[k])
        rows = np.array([r for m in ms for r in rows_of[m]])
        _, y, w = arrays(ms)
        head = fine_tune(backbone.net, a.fine_tune, values, rows, y, w, head, a.fine_tune_epochs, a.fine_tune_lr,
                         a.fine_tune_anchor, a.weight_decay)
        return head, lambda rows: tuned_features(backbone.net, a.fine_tune, values, np.asarray(rows))

    def arrays(ms):
        rows = [r for m in ms for r in rows_of[m]]
        y = np.array([label(views[r]["model"]) for r in rows], dtype=np.int64)
        w = np.array([weight_of[models[views[r]["model"]]["kind"] or OTHER] / len(rows_of[views[r]["model"]])
                      for r in rows], dtype=np.float32)
        return x[rows], y, w

    # Out-of-fold logits of the training models (split by model) for the temperature.
    # Shape cues, standardised by the training copies' mean and deviation; each model's copy 0 (as it is) is
    # the one scored.
    use_shape = a.shape_hidden >= 0
    cues, cue_names = read_cues(a.cues or os.path.join(a.dataset, "cues.csv")) if use_shape else ({}, [])
    if use_shape:
        missing = [m for m in sorted({v["model"] for v in views}) if 0 not in cues.get(m, {})]
        if missing:
            sys.exit(f"train_kinds: no shape cues of {len(missing)} models (first {missing[0]}); "
                     "rerun g2p_make_kind_dataset --cues-only, or --shape-hidden -1")
        every = np.stack([c for m in train_models for c in cues[m].values()])
        cue_mean, cue_scale = every.mean(axis=0), every.std(axis=0) + 1e-6

    def shape_arrays(ms):
        z, y, w = [], [], []
        for m in ms:
            for c in cues[m].values():
                z.append((c - cue_mean) / cue_scale)
                y.append(label(m))
                w.append(weight_of[models[m]["kind"] or OTHER] / len(cues[m]))
        return np.array(z, np.float32), np.array(y, np.int64), np.array(w, np.float32)

    def shape_of(shape_head, m):
        return shape_logp(shape_head, (cues[m][0] - cue_mean) / cue_scale) if use_shape else None

    rng = np.random.default_rng(0)
    order = list(rng.permutation(len(train_models)))
    oof_logits, oof_shape = {}, {}
    for f in range(a.folds):
        held = {train_models[i] for i in order[f::a.folds]}
        kept = [m for m in train_models if m not in held]
        head, feats = trained(kept)
        shape_head = train_shape_head(*shape_arrays(kept), len(classes), a.shape_hidden,
                                      a.shape_weight_decay) if use_shape else None
        with torch.no_grad():
            for m in held:
                oof_logits[m] = head(torch.from_numpy(feats(rows_of[m]))).numpy()
                oof_shape[m] = shape_of(shape_head, m)
    truth = {m: label(m) for m in train_models}
    temperature = fit_temperature(oof_logits, truth, a.fusion)
    shape_weight = fit_shape_weight({m: fuse(oof_logits[m], temperature, a.fusion) for m in train_models},
                                    oof_shape, truth) if use_shape else 0.0
    head, feats = trained(train_models)
    shape_head = train_shape_head(*shape_arrays(train_models), len(classes), a.shape_hidden,
                                  a.shape_weight_decay) if use_shape else None

    def score(ms, logits_of, shape_logp_of):
        results = []
        for m in ms:
            p = join(fuse(logits_of(m), temperature, a.fusion), shape_logp_of(m), shape_weight)
            # As the identifier reads it: the kinds only ("other" is a background class, left out).
            top = [classes[i] for i in np.argsort(-p) if i != 0][:3]
            results.append({"model": m, "truth": models[m]["kind"], "top3": top,
                            "confidence": float(p[1:].max()), "p_truth": float(p[index[models[m]["kind"]]])
                            if models[m]["kind"] in index else 0.0})
        return results

    oof = score(train_models, lambda m: oof_logits[m], lambda m: oof_shape[m])
    with torch.no_grad():
        val_models = sorted({v["model"] for v in views} - set(train_models))
        val = score(val_models, lambda m: head(torch.from_numpy(feats(rows_of[m]))).numpy(),
                    lambda m: shape_of(shape_head, m))

    # The fused confidence of the top kind, mapped so that it says how often the top kind is right: fitted on the
    # out-of-fold predictions of the training models, checked on validation.
    known_oof = [r for r in oof if r["truth"]]
    calibration = fit_platt([r["confidence"] for r in known_oof], [r["top3"][0] == r["truth"] for r in known_oof])
    for r in oof + val:
        r["raw_confidence"] = r["confidence"]
        r["confidence"] = platt(r["confidence"], calibration)

    def summary(results):
        known = [r for r in results if r["truth"]]
        top1 = sum(r["top3"][0] == r["truth"] for r in known)
        top3 = sum(r["truth"] in r["top3"] for r in known)
        covered = sum(r["truth"] in index for r in known)
        conf = [r["confidence"] for r in known]
        right = [r["top3"][0] == r["truth"] for r in known]
        diagram, ece = reliability(conf, right)
        confident = [r for r in known if r["confidence"] >= 0.6]
        return {"models": len(known), "kind_covered": covered, "top1": top1, "top3": top3,
                "confident_0.6": len(confident), "confident_right": sum(r["top3"][0] == r["truth"] for r in confident),
                "ece": ece, "reliability": diagram}

    report = {"features": layers, "fusion": a.fusion, "fine_tune": a.fine_tune or None,
              "fine_tune_epochs": a.fine_tune_epochs, "fine_tune_lr": a.fine_tune_lr,
              "fine_tune_anchor": a.fine_tune_anchor, "shape_hidden": a.shape_hidden,
              "shape_weight_decay": a.shape_weight_decay, "shape_weight": shape_weight, "balance": a.balance, "calibration": calibration, "min_models": a.min_models, "weight_decay": a.weight_decay, "epochs": a.epochs,
              "temperature": temperature, "classes": len(classes),
              "training_models": len(train_models), "training_views": sum(len(rows_of[m]) for m in train_models),
              "out_of_fold": summary(oof), "validation": summary(val), "validation_models": val}
    s = report["validation"]
    print(f"{a.features} fine-tune={a.fine_tune or '-'}/{a.fine_tune_epochs}/{a.fine_tune_lr} {a.fusion} balance={a.balance} wd={a.weight_decay} T={temperature:.2f} "
          f"shape={a.shape_hidden} swd={a.shape_weight_decay} w={shape_weight:.2f} classes={len(classes)}: "
          f"oof top1 {report['out_of_fold']['top1']}/{report['out_of_fold']['models']}, "
          f"val top1 {s['top1']}/{s['models']} top3 {s['top3']} (kind covered {s['kind_covered']}), "
          f"confident {s['confident_right']}/{s['confident_0.6']}, ECE {s['ece']:.3f} "
          f"(out of fold {report['out_of_fold']['ece']:.3f}), Platt {calibration[0]:.2f} {calibration[1]:.2f}")
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "report.json"), "w") as f:
        json.dump(report, f, indent=1)
    if a.no_export:
        return 0

    net = KindClassifier(backbone, head, temperature).eval()
    onnx_path = os.path.join(a.out, "g2p-kinds.onnx")
    export_onnx(net, onnx_path)
    with open(os.path.join(a.out, "g2p-kinds.txt"), "w") as f:
        f.write("".join(k + "\n" for k in kinds))
    libraries = Counter(models[m]["library"] for m in train_models)
    card = {
        "format": "g2p-kind-classifier-card", "version": 1,
        "model": "g2p-kinds.onnx", "labels": "g2p-kinds.txt",
        "architecture": "MobileNetV2 (Sandler et al. 2018; the ImageNet backbone of npm nsfwjs 4.4.0, "
                        + (f"frozen to {a.fine_tune}, its later layers fine-tuned here ({a.fine_tune_epochs} epochs)"
                           if a.fine_tune else "frozen") + f") to {'+'.join(layers)}, averaged over the image; a linear head over {len(classes)} classes "
                        "(a leading 'other', then the kinds of g2p-kinds.txt); softmax of the logits divided by "
                        "the calibration temperature" + ("; joined with a shape head over g2p::shape_cues() (\"shape\")"
                                                          if use_shape else ""),
        "input": {"name": "pixels", "layout": "NCHW", "shape": [1, 3, 224, 224], "channel_order": "RGB",
                  "normalization": "minus-one-to-one", "formula": "(pixel - 127.5) / 127.5", "views": "classifier_views(): 8 turntable views at "
                  "15 degrees, each cropped to the object on grey 128"},
        "notice": "MobileNetV2 of the npm package nsfwjs 4.4.0, Copyright (c) 2019 Infinite Red, Inc., MIT licence "
                  "(NOTICE.md); head trained on the models of ATTRIBUTION-kinds.md",
        "fusion": a.fusion, "temperature": temperature,
        "calibration": {"platt": list(calibration),
                        "about": "a kind's confidence = sigmoid(a * logit(p) + b), p its probability from the views "
                                 "(joined with the shape head's where the card has one): how often a top kind of "
                                 "that confidence was right, out of fold"},
        "data": {"libraries": dict(libraries), "training_models": len(train_models),
                 "views": report["training_views"],
                 "source": "Debian's sweethome3d-furniture 1.8-1 (BlendSwap-CC-0: CC0; BlendSwap-CC-BY, Scopia, "
                           "Reallusion: CC BY 3.0); data/mass-ranges/val.json's models and KatorLegaz held out"},
        "kinds": {k: counts[k] for k in kinds},
        "other_models": sum(1 for m in train_models if label(m) == 0),
        "kinds_below_min_models": {k: n for k, n in counts.items() if k != OTHER and n < a.min_models},
        "shape": shape_card(shape_head, cue_names, cue_mean, cue_scale, shape_weight) if use_shape else None,
        "scores": {"out_of_fold": {k: v for k, v in report["out_of_fold"].items() if k != "reliability"},
                   "validation": {k: v for k, v in report["validation"].items() if k != "reliability"}},
    }
    with open(os.path.join(a.out, "g2p-kinds.json"), "w") as f:
        f.write(card_text(card))
    return 0


if __name__ == "__main__":
    sys.exit(main())
