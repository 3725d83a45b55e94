"""Run folders read back as networks: a train.py or soup.py output folder (training.json with best.pt, or its
export alone) or an ensemble.py one (all its members; "FOLDER#K" member K), each member rebuilt with the settings its
training.json records. train.py (--init, --teacher), ensemble.py and soup.py read their runs through it.
"""
import json
import os

import torch

from .model import UNet, context_unet
from .onnx_weights import recover_members, recover_state


# The settings that decide which models a run validated on; they must agree across members.
SPLIT_KEYS = ("split_seed", "val_share", "val_library")


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
    model = UNet(inputs=inputs)
    if settings.get("context"):
        if not context:
            raise ValueError(f"{settings['out']} was trained with a pretrained context encoder: pass --context")
        model = context_unet(model, settings, context)
    return model, inputs


_RECOVERED = {}  # (ensemble file, context) -> its members' state dicts: an ensemble is taken apart once


def member_state(record, context):
    """The weights of ensemble member record["member"] (a record from read_runs), recovered from its ensemble's
    file together with its fellow members'."""
    key = (record["weights_from"], context)
    if key not in _RECOVERED:
        built = [network(m, context) for m in record["ensemble_members"]]
        inputs = {n for _, n in built}
        if len(inputs) != 1:
            raise ValueError(f"{record['weights_from']}: its members take different inputs")
        _RECOVERED[key] = recover_members([m for m, _ in built], record["weights_from"], inputs.pop(),
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
            model.load_state_dict(recover_state(model, record["weights_from"], inputs,
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
