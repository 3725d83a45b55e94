"""The training data: g2p_make_dataset's folders read as training and validation rows (whole models held out for
validation), their images and labels decoded into a torch Dataset, the augmentations and the class weights
(docs/training.md, "Data" to "Model and training").

The lowest layer of tools/training (the order is LAYERS in __init__.py): it imports no other module of the package.
"""
import csv
import hashlib
import os
import random

import numpy as np
import torch
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
