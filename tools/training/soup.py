#!/usr/bin/python3
"""Averages the weights of runs that started from one network (a uniform "model soup") into one run folder.

    python3 tools/training/soup.py OUT RUN RUN [RUN ...] [--context MODELS] [--bn best] [--bn-batches 64]

Each RUN is a train.py output folder (best.pt and training.json; or its export alone when the run exported without a
logit adjustment, tau 0), all of one architecture and validated on the same models. The members' weights before
their logit adjustment are averaged; so are the batch normalisations' running statistics, or they are recomputed
on training images with the averaged weights (Izmailov et al. 2018, "Averaging weights leads to wider optima and
better generalization", do so after averaging): --bn average, recompute, or best (both, the one with the higher
validation mIoU kept). The logit adjustment tau is then picked on the validation models as train.py picks it.

A weight average is as good as the members' ensemble, at the cost of one network, only where the members lie in
one basin of the loss: networks fine-tuned from one starting point with different batches (Wortsman et al. 2022,
"Model soups"; Frankle et al. 2020, "Linear mode connectivity and the lottery ticket hypothesis"). Networks trained
from different weights average to noise; join those with ensemble.py. The tool prints the soup's validation mIoU
beside its members' as they were exported, so a soup that falls below them is seen at once.

OUT receives what train.py leaves (best.pt, the averaged weights before the adjustment; g2p-materials.onnx with it
folded in; its model card; training.json, with the members' records under "soup"), so OUT serves wherever a run
does: ensemble.py, train.py --init, onnx_weights.py. The files replace OUT's only once all are written.
docs/training-log.md, "Weight averages of the two seeds", gives the measured effect.
"""
import argparse
import json
import os
import random
import sys

import numpy as np
import torch
import torch.nn as nn

if __name__ == "__main__" and not __package__:  # run as a script: import the package as python3 -m does
    sys.path[0] = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    __package__ = "tools.training"

from .data import Dataset, class_weights, training_rows, validation_subsample  # noqa: E402
from .export import RUN_FILES, export_onnx, staged_export, write_model_card  # noqa: E402
from .metrics import confusion, mean_iou  # noqa: E402
from .model import context_kinds  # noqa: E402
from .runs import build_member, network, read_runs, split_mismatch  # noqa: E402

# Settings that decide the network's shape and what it sees; members must agree on them to be averaged.
ARCHITECTURE_KEYS = ("normals", "context_kind", "extra_context", "context_upsample", "export_size")
BN_CHOICES = ("average", "recompute", "best")


def average_states(states):
    """The element-wise mean of state dicts with the same keys and shapes. Floating tensors are averaged in double
    precision; integer ones (batch normalisation's num_batches_tracked, which nothing computes with) keep the first
    member's value. ValueError names a key or shape that differs."""
    keys = list(states[0])
    for k, state in enumerate(states[1:], 1):
        if list(state) != keys:
            raise ValueError(f"member {k} has other weights than member 0 (another architecture)")
    mean = {}
    for key in keys:
        tensors = [s[key] for s in states]
        if any(t.shape != tensors[0].shape for t in tensors):
            raise ValueError(f"{key}: the members' shapes differ ({', '.join(str(tuple(t.shape)) for t in tensors)})")
        if tensors[0].is_floating_point():
            mean[key] = (sum(t.double() for t in tensors) / len(tensors)).to(tensors[0].dtype)
        else:
            mean[key] = tensors[0].clone()
    return mean


def recompute_batch_norm(model, batches):
    """Replaces every batch normalisation's running mean and variance by their averages over `batches` (input
    tensors) in training mode, as each layer sees them through the layers before it (torch's update_bn does the
    same). Returns the number of batch normalisations."""
    bns = [m for m in model.modules() if isinstance(m, nn.modules.batchnorm._BatchNorm)]
    momenta = [m.momentum for m in bns]
    for m in bns:
        m.reset_running_stats()
        m.momentum = None  # a cumulative average over the batches, not an exponential one
    was_training = model.training
    model.train()
    try:
        with torch.no_grad():
            for x in batches:
                model(x)
    finally:
        for m, momentum in zip(bns, momenta):
            m.momentum = momentum
        model.train(was_training)
    return len(bns)


def member_state(record, state, context):
    """A member's weights before its logit adjustment: best.pt's, or those recovered from its export (possible only
    when it exported with tau 0, so that nothing is folded in)."""
    if state is not None:
        return state
    model, _ = build_member(record, None, context, None)  # refuses a folded-in adjustment
    return model.state_dict()


def check_members(labels, records, first, sha):
    """ValueError naming the first member that cannot be averaged with the first one."""
    for label, record in zip(labels, records):
        differs = split_mismatch(record, first, sha)
        if differs:
            raise ValueError(f"{label}: validated on other models than {labels[0]} ({differs} differs)")
        s = record["settings"]
        other = [k for k in ARCHITECTURE_KEYS if s.get(k) != first.get(k)]
        if bool(s.get("context")) != bool(first.get("context")):
            other.append("context")
        if other:
            raise ValueError(f"{label}: {', '.join(other)} differ from {labels[0]}'s; only one architecture averages")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out")
    ap.add_argument("runs", nargs="+", metavar="RUN", help="train.py output folders (best.pt and training.json)")
    ap.add_argument("--dataset", default="", help="the dataset the members trained on (default: the first's)")
    ap.add_argument("--context", default="", help="folder of the members' --context encoder, as for ensemble.py")
    ap.add_argument("--bn", default="best", choices=BN_CHOICES,
                    help="batch normalisation statistics: the members' averaged, recomputed on training images, or "
                         "both tried and the better on validation kept (default)")
    ap.add_argument("--bn-batches", type=int, default=64,
                    help="training batches (of the first member's batch size) for --bn recompute (default 64)")
    ap.add_argument("--seed", type=int, default=1, help="random seed of the recomputation's images and augmentations")
    ap.add_argument("--overwrite", action="store_true", help="write into an OUT that already holds a run")
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args()
    held = [name for name in RUN_FILES if os.path.exists(os.path.join(a.out, name))]
    if held and not a.overwrite:
        ap.error(f"{a.out}: already holds a run ({', '.join(held)}); pick another folder or pass --overwrite")
    if a.bn_batches < 1:
        ap.error("--bn-batches must be at least 1")
    torch.set_num_threads(a.threads)
    random.seed(a.seed)
    np.random.seed(a.seed)
    torch.manual_seed(a.seed)
    try:
        runs = [member for spec in a.runs for member in read_runs(spec)]
    except ValueError as e:
        ap.error(str(e))
    if len(runs) < 2:
        ap.error(f"a soup needs at least two members; {' '.join(a.runs)} has one")
    labels = [label for label, _, _ in runs]
    records = [r for _, r, _ in runs]
    for record in records:  # runs from before --split-seed split with --seed
        record["settings"].setdefault("split_seed", record["settings"]["seed"])
    first = records[0]["settings"]
    dataset = a.dataset or first["dataset"]
    try:
        rows, val_rows, sha, _ = training_rows(dataset, [], first["val_share"], first["split_seed"],
                                               first.get("val_library", ""))
        check_members(labels, records, first, sha)
        model, inputs = network(records[0], a.context)
        soup = average_states([member_state(r, s, a.context) for _, r, s in runs])
        model.load_state_dict(soup)
    except (ValueError, RuntimeError) as e:
        ap.error(str(e))

    val_rows = validation_subsample(val_rows)
    _, counts = class_weights(rows, first["balance"])
    prior = torch.tensor(counts / max(counts.sum(), 1), dtype=torch.float32)
    taus = [0.0, 0.25, 0.5, 0.75, 1.0]
    adjust = [torch.where(prior > 0, -t * torch.log(prior.clamp(min=1e-12)), torch.full_like(prior, -30.0))
              for t in taus]
    size = first["export_size"]
    val_data = torch.utils.data.DataLoader(Dataset(dataset, val_rows, first["size"], False,
                                                   normals=inputs == 6), batch_size=32)

    def validate():
        return [mean_iou(m) for m in confusion(model, val_data, size, adjust, "cpu")]

    variants = {}  # --bn choice -> (its state, its validation mIoU by tau)
    if a.bn in ("average", "best"):
        variants["average"] = (soup, validate())
    if a.bn in ("recompute", "best"):
        images = Dataset(dataset, rows, first["size"], True, first.get("colour_jitter", 1.0), inputs == 6,
                         first.get("normal_dropout", 0.0))
        loader = torch.utils.data.DataLoader(images, batch_size=first.get("batch", 16), shuffle=True,
                                             drop_last=True, generator=torch.Generator().manual_seed(a.seed))
        model.load_state_dict(soup)
        recompute_batch_norm(model, (x for _, (x, _) in zip(range(a.bn_batches), loader)))
        variants["recompute"] = ({k: v.clone() for k, v in model.state_dict().items()}, validate())
    for name, (_, scores) in variants.items():
        print(f"validation mIoU by tau, batch normalisation {name}: "
              + ", ".join(f"{t}: {100 * s:.1f} %" for t, s in zip(taus, scores)), flush=True)
    bn = max(variants, key=lambda name: np.nanmax(variants[name][1]))
    state, scores = variants[bn]
    k = int(np.nanargmax(scores))
    exported = {"epoch": None, "tau": taus[k], "val_miou": scores[k]}
    members_val = [r["exported"]["val_miou"] for r in records]
    print(f"soup: batch normalisation {bn}, tau {taus[k]}, validation mIoU {100 * scores[k]:.1f} % (members as "
          f"exported: {', '.join(f'{100 * v:.1f}' for v in members_val)} %, mean {100 * np.mean(members_val):.1f})",
          flush=True)

    model.load_state_dict(state)
    with torch.no_grad():
        model.head.bias += adjust[k]
    model.eval()
    settings = dict(first, out=a.out, init="", epochs=0)
    with staged_export(a.out) as stage:
        torch.save(state, os.path.join(stage, "best.pt"))
        export_onnx(model, inputs, size, os.path.join(stage, "g2p-materials.onnx"))
        write_model_card(stage, size, inputs == 6, context_kinds(first))
        with open(os.path.join(stage, "training.json"), "w") as f:
            json.dump({"settings": settings, "parameters": sum(p.numel() for p in model.parameters()),
                       "images": len(rows), "validation_images": len(val_rows), "exported": exported,
                       "manifest_sha256": sha, "more_manifest_sha256": [],
                       "soup": {"members": labels, "batch_norm": bn, "bn_batches": a.bn_batches if bn == "recompute"
                                else 0, "seed": a.seed,
                                "validation_miou": {name: dict(zip(map(str, taus), s))
                                                    for name, (_, s) in variants.items()},
                                "member_records": records},
                       "torch": torch.__version__}, f, indent=2)
            f.write("\n")
    print(f"{len(runs)} members -> {os.path.join(a.out, 'g2p-materials.onnx')}", flush=True)


if __name__ == "__main__":
    main()
