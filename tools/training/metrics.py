"""Validation scores: the pixel confusion matrices of a network on validation images, seen as the `onnx` backend
sees a view, and their mean IoU. train.py picks its epoch and logit adjustment by them; ensemble.py, soup.py and
colour_baseline.py report them.
"""
import torch
import torch.nn.functional as F

from .data import CLASSES


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
