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
docs/training.md, "An ensemble of two lineages", gives the measured effect.
"""
import argparse
import json
import os
import sys

import torch
import torch.nn as nn
import torch.nn.functional as F

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import quantize  # noqa: E402  (tools/training/quantize.py)
import train  # noqa: E402  (tools/training/train.py)

# The settings that decide which models a run validated on; they must agree across members.
SPLIT_KEYS = ("split_seed", "val_share", "val_library")


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


def split_member(spec):
    """(path, member index or None) of a RUN argument, "FOLDER" or "FOLDER#K" (K from 0)."""
    path, mark, member = spec.rpartition("#")
    if mark and member.isdigit():
        return path, int(member)
    return spec, None


def read_runs(spec):
    """The members a RUN argument stands for, as (label, training.json record, best.pt's state dict) triples.

    A train.py output folder is one member. A folder whose checkpoints are gone (a run from another machine) serves
    through its exported g2p-materials.onnx: the state is then None and the record's "weights_from" names the file,
    whose weights build_member recovers (onnx_weights.py). An ensemble.py output folder (the shipped
    libg2p/data/models/ is one) stands for all its members, "FOLDER#K" for member K alone (from 0): their records
    are those the ensemble keeps, with "weights_from" its file and "member" the index. ValueError names what is
    missing."""
    folder, only = split_member(spec)
    paths = {name: os.path.join(folder, name) for name in ("training.json", "best.pt", "g2p-materials.onnx")}
    if not os.path.isfile(paths["training.json"]):
        raise ValueError(f"{paths['training.json']}: not found (a member is a train.py or ensemble.py output folder)")
    with open(paths["training.json"]) as f:
        record = json.load(f)
    if "ensemble" in record:
        members = record.get("members") or []
        if not members:
            raise ValueError(f"{paths['training.json']}: an ensemble without members")
        if only is not None and only >= len(members):
            raise ValueError(f"{spec}: the ensemble has {len(members)} members (#0 to #{len(members) - 1})")
        if not os.path.isfile(paths["g2p-materials.onnx"]):
            raise ValueError(f"{folder}: an ensemble without its g2p-materials.onnx")
        runs = []
        for k, member in enumerate(members):
            if only is not None and k != only:
                continue
            member = dict(member, weights_from=os.path.abspath(paths["g2p-materials.onnx"]), member=k)
            member["ensemble_members"] = [dict(m) for m in members]
            runs.append((f"{folder}#{k}", member, None))
        return runs
    if only is not None:
        raise ValueError(f"{spec}: {folder} is one network, not an ensemble (drop #{only})")
    if not record.get("exported"):
        raise ValueError(f"{paths['training.json']}: no validated epoch was exported (trained without validation)")
    if os.path.isfile(paths["best.pt"]):
        return [(spec, record, torch.load(paths["best.pt"], map_location="cpu"))]
    if not os.path.isfile(paths["g2p-materials.onnx"]):
        raise ValueError(f"{folder}: holds neither best.pt nor g2p-materials.onnx (the run's weights)")
    record["weights_from"] = os.path.abspath(paths["g2p-materials.onnx"])
    return [(spec, record, None)]


def network(record, context):
    """(the untrained network a run's recorded settings describe, its input channels)."""
    settings = record["settings"]
    inputs = 6 if settings.get("normals") else 3
    model = train.UNet(inputs=inputs)
    if settings.get("context"):
        if not context:
            raise ValueError(f"{settings['out']} was trained with a pretrained context encoder: pass --context")
        model = train.context_unet(model, settings, context)
    return model, inputs


_RECOVERED = {}  # (ensemble file, context) -> its members' state dicts: an ensemble is taken apart once


def member_state(record, context):
    """The weights of ensemble member record["member"] (a record from read_runs), recovered from its ensemble's
    file together with its fellow members'."""
    key = (record["weights_from"], context)
    if key not in _RECOVERED:
        import onnx_weights  # tools/training/onnx_weights.py
        built = [network(m, context) for m in record["ensemble_members"]]
        inputs = {n for _, n in built}
        if len(inputs) != 1:
            raise ValueError(f"{record['weights_from']}: its members take different inputs")
        _RECOVERED[key] = onnx_weights.recover_members([m for m, _ in built], record["weights_from"], inputs.pop(),
                                                       record["settings"]["export_size"])
    return _RECOVERED[key][record["member"]]


def build_member(record, state, context, prior):
    """The network a run exported: its architecture from the recorded settings, its best weights and its logit
    adjustment folded into the classifier's bias, as train.py exports it (with `prior` None, no adjustment). With
    `state` None the weights are recovered from record["weights_from"], its export (or its ensemble's), which has
    the adjustment in."""
    model, inputs = network(record, context)
    tau = record["exported"]["tau"]
    if state is None:
        if prior is None and tau != 0:
            raise ValueError(f"{record['weights_from']}: its logit adjustment (tau {tau}) is folded into the weights; "
                             f"without its best.pt the network before the adjustment is not known")
        if "member" in record:
            model.load_state_dict(member_state(record, context))
        else:
            import onnx_weights  # tools/training/onnx_weights.py
            model.load_state_dict(onnx_weights.recover_state(model, record["weights_from"], inputs,
                                                             record["settings"]["export_size"]))
        return model.eval(), inputs
    model.load_state_dict(state)
    if prior is None:  # the network's own probabilities, before the logit adjustment (a teacher's)
        return model.eval(), inputs
    with torch.no_grad():
        model.head.bias += torch.where(prior > 0, -tau * torch.log(prior.clamp(min=1e-12)),
                                       torch.full_like(prior, -30.0))
    return model.eval(), inputs


def split_mismatch(record, settings, sha):
    """What makes a run's validation models differ from those of `settings` on the dataset whose manifest has
    SHA-256 `sha` ("" when they are the same): "manifest" or the differing split settings."""
    if record["manifest_sha256"] != sha:
        return "manifest"
    own = dict(record["settings"])
    own.setdefault("split_seed", own.get("seed"))  # runs from before --split-seed split with --seed
    return ", ".join(k for k in SPLIT_KEYS if own.get(k, "") != settings.get(k, ""))


def export_ensemble(model, inputs, size, onnx_path, int8=True):
    """Writes `model` (an Ensemble) to `onnx_path` as the `onnx` backend reads it: exported as train.py exports a
    run, the Identity nodes the exporter writes for weights the members share exactly (their fixed input conversion)
    replaced by constants, since OpenCV 4.6's importer cannot parse an Identity whose input is a constant, and with
    `int8` the convolution weights in 8 bits (quantize.py). Returns quantize.py's counts (None without `int8`)."""
    import onnx  # python3-onnx
    import onnx_weights  # tools/training/onnx_weights.py
    train.export_onnx(model, inputs, size, onnx_path)
    exported = onnx.load(onnx_path)
    onnx_weights.inline_identity_constants(exported)
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
    rows, val_rows, sha, _ = train.training_rows(dataset, [], first["val_share"], first["split_seed"],
                                                 first.get("val_library", ""))
    for run, record in zip(labels, records):
        s = record["settings"]
        differs = split_mismatch(record, first, sha)
        if differs:
            ap.error(f"{run}: validated on other models than {dataset} with {labels[0]}'s split "
                     f"({differs} differs); its score on these validation images would include its training models")
        if record["settings"].get("export_size") != first.get("export_size"):
            ap.error(f"{run}: export size {s.get('export_size')} differs from {labels[0]}'s")
    val_rows = train.validation_subsample(val_rows)
    _, counts = train.class_weights(rows, first["balance"])
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
    val_data = torch.utils.data.DataLoader(train.Dataset(dataset, val_rows, first["size"], False,
                                                         normals=inputs == 6), batch_size=32)
    zero = [torch.zeros(len(train.CLASSES))]
    scores = {run: train.mean_iou(train.confusion(m, val_data, size, zero, "cpu")[0])
              for run, m in zip(labels, members)}
    scores["ensemble"] = train.mean_iou(train.confusion(model, val_data, size, zero, "cpu")[0])
    for name, score in scores.items():
        print(f"validation mIoU {100 * score:.1f} %: {name}", flush=True)

    with train.staged_export(a.out) as stage:  # OUT keeps what it held unless the whole export succeeds
        onnx_path = os.path.join(stage, "g2p-materials.onnx")
        quantised = export_ensemble(model, inputs, size, onnx_path, int8=not a.float_weights)
        train.write_model_card(stage, size, inputs == 6,
                               list(dict.fromkeys(k for r in records for k in train.context_kinds(r["settings"]))))
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
