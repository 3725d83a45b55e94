"""What a run writes into its OUT folder: the ONNX export (every script of tools/training exports through
export_onnx), the model card the `onnx` backend reads (docs/segment.md) with the notice of any pretrained encoder
inside, the checkpoints, and the staged replacement of OUT's files (RUN_FILES), so that a failed export leaves OUT
as it was. runs.py reads such folders back.
"""
import contextlib
import json
import os
import shutil
import tempfile

import torch

from .data import CLASSES, MEAN, STD
from .model import CONTEXTS


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


def mark_notice(onnx_path, notice):
    """Writes the third-party notice into the ONNX file's metadata, so that a copy of the file alone carries it."""
    import onnx  # python3-onnx
    model = onnx.load(onnx_path)
    model.doc_string = notice
    entry = model.metadata_props.add()
    entry.key, entry.value = "notice", notice
    onnx.save(model, onnx_path)


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
