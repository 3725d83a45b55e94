#!/usr/bin/python3
"""Combines networks trained by train.py into one ONNX model whose output is their averaged logits.

    python3 tools/training/ensemble.py OUT RUN RUN [RUN ...] [--context MODELS] [--float-weights] [--threads 2]

Each RUN is a train.py output folder (best.pt and training.json; without best.pt, its exported g2p-materials.onnx,
whose weights onnx_weights.py recovers) or an ensemble.py output folder, which stands for all its members
("FOLDER#K": member K alone, from 0); the shipped libg2p/data/models/ is either kind. Every member is rebuilt with the settings its
training.json records, its exported logit adjustment (tau) folded in, and the ensemble outputs the mean of the
members' logits, whose softmax is the normalised geometric mean of their probabilities (Lakshminarayanan et al. 2017,
"Simple and scalable predictive uncertainty estimation using deep ensembles", average independently trained
networks). Unlike a weight average (a "model soup"), the members need not share a lineage: networks that
started from different weights make different errors, and averaging their predictions cancels part of them.

The members must have been validated on the same models (the same dataset manifest, split seed, validation share or
validation library), so that none of them was trained on the validation models the ensemble is scored on;
anything else is refused. The convolution weights are stored as 8-bit integers (quantize.py), so that an
ensemble of four members is about the size of one member in float (18.6 against 18.3 MB); --float-weights keeps
them in float. OUT receives g2p-materials.onnx, its model card and training.json (the members' own records, and
the validation mIoU of each member and of the ensemble, in float, on the same images); they replace OUT's only once
all three are written, so a failed export leaves OUT as it was.
docs/training-log.md, "An ensemble of two lineages", gives the measured effect.
"""
import argparse
import json
import os
import sys

import torch

if __name__ == "__main__" and not __package__:  # run as a script: import the package as python3 -m does
    sys.path[0] = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    __package__ = "tools.training"

from . import quantize  # noqa: E402
from .data import CLASSES, Dataset, class_weights, training_rows, validation_subsample  # noqa: E402
from .export import export_onnx, staged_export, write_model_card  # noqa: E402
from .metrics import confusion, mean_iou  # noqa: E402
from .model import COMBINES, Ensemble, context_kinds  # noqa: E402
from .onnx_weights import inline_identity_constants  # noqa: E402
from .runs import build_member, read_runs, split_mismatch  # noqa: E402


def export_ensemble(model, inputs, size, onnx_path, int8=True):
    """Writes `model` (an Ensemble) to `onnx_path` as the `onnx` backend reads it: exported as train.py exports a
    run, the Identity nodes the exporter writes for weights the members share exactly (their fixed input conversion)
    replaced by constants, since OpenCV 4.6's importer cannot parse an Identity whose input is a constant, and with
    `int8` the convolution weights in 8 bits (quantize.py). Returns quantize.py's counts (None without `int8`)."""
    import onnx  # python3-onnx
    export_onnx(model, inputs, size, onnx_path)
    exported = onnx.load(onnx_path)
    inline_identity_constants(exported)
    quantised = None
    if int8:
        count, before, after = quantize.quantize_conv_weights(exported)
        quantised = {"convolutions": count, "weight_bytes_before": before, "weight_bytes_after": after}
    onnx.checker.check_model(exported)
    onnx.save(exported, onnx_path)
    return quantised


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out")
    ap.add_argument("runs", nargs="+", metavar="RUN",
                    help="train.py output folders (training.json, and best.pt or g2p-materials.onnx), or ensemble.py "
                         "ones (all their members; FOLDER#K: member K, from 0)")
    ap.add_argument("--dataset", default="",
                    help="the dataset the members were validated on (default: the first member's recorded one)")
    ap.add_argument("--context", default="",
                    help="folder of the members' --context encoder (nanodet.json/.bin, or mobilenet_v2.json/.bin for "
                         "--context-kind mobilenet_v2); --extra-context encoders are read where training.json says")
    ap.add_argument("--float-weights", action="store_true", help="keep the weights in float (4x the size)")
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args()
    torch.set_num_threads(a.threads)
    try:
        runs = [member for spec in a.runs for member in read_runs(spec)]
    except ValueError as e:
        ap.error(str(e))
    if len(runs) < 2:  # one ensemble folder alone is enough: it is exported again (with today's combine)
        ap.error(f"an ensemble needs at least two members; {' '.join(a.runs)} has one")
    labels = [label for label, _, _ in runs]
    records = [r for _, r, _ in runs]
    first = records[0]["settings"]
    dataset = a.dataset or first["dataset"]
    for record in records:  # runs from before --split-seed split with --seed
        record["settings"].setdefault("split_seed", record["settings"]["seed"])
    rows, val_rows, sha, _ = training_rows(dataset, [], first["val_share"], first["split_seed"],
                                           first.get("val_library", ""))
    for run, record in zip(labels, records):
        s = record["settings"]
        differs = split_mismatch(record, first, sha)
        if differs:
            ap.error(f"{run}: validated on other models than {dataset} with {labels[0]}'s split "
                     f"({differs} differs); its score on these validation images would include its training models")
        if record["settings"].get("export_size") != first.get("export_size"):
            ap.error(f"{run}: export size {s.get('export_size')} differs from {labels[0]}'s")
    val_rows = validation_subsample(val_rows)
    _, counts = class_weights(rows, first["balance"])
    prior = torch.tensor(counts / max(counts.sum(), 1), dtype=torch.float32)
    try:
        built = [build_member(record, state, a.context, prior) for _, record, state in runs]
    except (ValueError, RuntimeError) as e:
        ap.error(str(e))
    inputs = {n for _, n in built}
    if len(inputs) != 1:
        ap.error("the members take different inputs (some with normals, some without)")
    inputs = inputs.pop()
    members = [m for m, _ in built]
    model = Ensemble(members).eval()

    size = first["export_size"]
    val_data = torch.utils.data.DataLoader(Dataset(dataset, val_rows, first["size"], False,
                                                   normals=inputs == 6), batch_size=32)
    zero = [torch.zeros(len(CLASSES))]
    scores = {run: mean_iou(confusion(m, val_data, size, zero, "cpu")[0])
              for run, m in zip(labels, members)}
    scores["ensemble"] = mean_iou(confusion(model, val_data, size, zero, "cpu")[0])
    for name, score in scores.items():
        print(f"validation mIoU {100 * score:.1f} %: {name}", flush=True)

    with staged_export(a.out) as stage:  # OUT keeps what it held unless the whole export succeeds
        onnx_path = os.path.join(stage, "g2p-materials.onnx")
        quantised = export_ensemble(model, inputs, size, onnx_path, int8=not a.float_weights)
        write_model_card(stage, size, inputs == 6,
                         list(dict.fromkeys(k for r in records for k in context_kinds(r["settings"]))))
        with open(os.path.join(stage, "training.json"), "w") as f:
            json.dump({"ensemble": {"members": labels, "combine": COMBINES[model.combine], "int8_weights": quantised,
                                    "dataset": dataset,
                                    "manifest_sha256": sha, "validation_images": len(val_rows),
                                    "validation_miou": scores},
                       "members": [{k: v for k, v in r.items() if k != "ensemble_members"} for r in records],
                       "torch": torch.__version__}, f, indent=2)
            f.write("\n")
        megabytes = os.path.getsize(onnx_path) / 1e6
    print(f"{len(members)} members -> {os.path.join(a.out, 'g2p-materials.onnx')} ({megabytes:.1f} MB)", flush=True)


if __name__ == "__main__":
    main()
