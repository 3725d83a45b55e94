#!/usr/bin/python3
"""Reference decoder for the object detector export_detector.py writes (libg2p/data/models/g2p-objects-nanodet.onnx
and its card): runs it with OpenCV's dnn module on images, decodes NanoDet's per-stride outputs into boxes as the
card's "decode" section says, and votes over several views of one object.

    python3 tools/training/detect_objects.py IMAGE... [--card libg2p/data/models/g2p-objects-nanodet.json]
        [--threshold 0.35] [--background 128,128,128] [--top 3] [--json OUT.json] [--draw DIR]

    g2p render MODEL -o OUT --layout turntable --views 8
    python3 tools/training/detect_objects.py OUT/views/view_*_rgb.png --background 128,128,128

Decoding (NanoDet's GFL head): for stride s (8, 16, 32) the grid is (416 / s) x (416 / s); cell i sits at
row = i // grid, column = i % grid, centre ((column + 0.5) s, (row + 0.5) s). Each side's distance is s times the
expectation of a softmax over reg_max + 1 = 11 bins (sides left, top, right, bottom, in that order); the box is
centre - left/top .. centre + right/bottom, clamped to the input and scaled back to the image. Scores are already
sigmoid-ed. Per level the 1000 cells of highest maximum score are kept (NanoDet's nms_pre); then, per class, every
(cell, class) pair above the threshold goes through greedy NMS (IoU > nms_iou suppressed); at most 100 are returned.

The vote over the images given: for each class, the mean over images of the class's highest score anywhere in the
image (threshold-free). Turntable views (eye level) on a mid-grey background detect best on our renders
(docs/training.md, "The object detector").
"""
import argparse
import json
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CARD = os.path.join(ROOT, "libg2p", "data", "models", "g2p-objects-nanodet.json")


class Detector:
    def __init__(self, card_path=CARD, onnx_path=None):
        import cv2  # python3-opencv
        with open(card_path) as f:
            self.card = json.load(f)
        if self.card.get("format") != "g2p-onnx-detector-card" or self.card.get("version") != 1:
            raise ValueError(f"{card_path}: not a g2p-onnx-detector-card version 1")
        path = onnx_path or os.path.join(os.path.dirname(card_path), self.card["model"])
        self.net = cv2.dnn.readNetFromONNX(path)
        self.net.setPreferableBackend(cv2.dnn.DNN_BACKEND_OPENCV)
        self.net.setPreferableTarget(cv2.dnn.DNN_TARGET_CPU)
        self.outputs = self.card["outputs"]
        self.classes = self.card["classes"]

    def blob(self, bgr):
        """The network input (1 x 3 x H x W float32) for an 8-bit BGR image, as the card's "input" says."""
        import cv2
        inp = self.card["input"]
        img = cv2.resize(bgr, (inp["width"], inp["height"]), interpolation=cv2.INTER_LINEAR).astype(np.float32)
        if inp["channel_order"] == "RGB":
            img = img[:, :, ::-1]
        img = (img * inp["scale"] - np.float32(inp["mean"])) / np.float32(inp["std"])
        return np.ascontiguousarray(img.transpose(2, 0, 1)[None], dtype=np.float32)

    def raw(self, bgr):
        """{output name: array} for one image."""
        self.net.setInput(self.blob(bgr), self.card["input"]["name"])
        names = [o["name"] for o in self.outputs]
        return dict(zip(names, self.net.forward(names)))

    def decode(self, raw, image_size, threshold=None, nms_pre=1000):
        """[(class name, score, (x1, y1, x2, y2) in image pixels)], best first."""
        d = self.card["decode"]
        inp = self.card["input"]
        threshold = d["score_threshold"] if threshold is None else threshold
        bins = d["reg_max"] + 1
        project = np.arange(bins, dtype=np.float32)
        boxes, scores = [], []
        for stride in d["strides"]:
            s = raw[next(o["name"] for o in self.outputs if o["name"].startswith("scores") and o["stride"] == stride)][0]
            r = raw[next(o["name"] for o in self.outputs if o["name"].startswith("boxes") and o["stride"] == stride)][0]
            grid_w = inp["width"] // stride
            cells = np.arange(s.shape[0])
            if s.shape[0] > nms_pre:
                cells = np.argsort(-s.max(1), kind="stable")[:nms_pre]
            cx = (cells % grid_w + 0.5) * stride
            cy = (cells // grid_w + 0.5) * stride
            logits = r[cells].reshape(-1, 4, bins)
            p = np.exp(logits - logits.max(-1, keepdims=True))
            dist = (p / p.sum(-1, keepdims=True)) @ project * stride  # (n, 4): left, top, right, bottom
            b = np.stack([cx - dist[:, 0], cy - dist[:, 1], cx + dist[:, 2], cy + dist[:, 3]], 1)
            b[:, 0::2] = b[:, 0::2].clip(0, inp["width"])
            b[:, 1::2] = b[:, 1::2].clip(0, inp["height"])
            boxes.append(b)
            scores.append(s[cells])
        boxes, scores = np.concatenate(boxes), np.concatenate(scores)
        sx, sy = image_size[0] / inp["width"], image_size[1] / inp["height"]
        found = []
        for c in range(scores.shape[1]):
            keep = np.nonzero(scores[:, c] > threshold)[0]
            for i in nms(boxes[keep], scores[keep, c], d["nms_iou"]):
                x1, y1, x2, y2 = boxes[keep[i]]
                found.append((self.classes[c], float(scores[keep[i], c]), (x1 * sx, y1 * sy, x2 * sx, y2 * sy)))
        found.sort(key=lambda f: -f[1])
        return found[:d.get("max_detections", 100)]

    def best_per_class(self, raw):
        """The highest score of each class anywhere in the view (the vote's ballot)."""
        return np.max([raw[o["name"]][0].max(0) for o in self.outputs if o["name"].startswith("scores")], 0)

    def detect(self, bgr, threshold=None):
        raw = self.raw(bgr)
        return self.decode(raw, (bgr.shape[1], bgr.shape[0]), threshold), raw


def nms(boxes, scores, iou):
    """Indices kept by greedy non-maximum suppression, best first."""
    order = np.argsort(-scores, kind="stable")
    kept = []
    area = (boxes[:, 2] - boxes[:, 0]).clip(0) * (boxes[:, 3] - boxes[:, 1]).clip(0)
    while order.size:
        i = order[0]
        kept.append(int(i))
        rest = order[1:]
        w = (np.minimum(boxes[i, 2], boxes[rest, 2]) - np.maximum(boxes[i, 0], boxes[rest, 0])).clip(0)
        h = (np.minimum(boxes[i, 3], boxes[rest, 3]) - np.maximum(boxes[i, 1], boxes[rest, 1])).clip(0)
        inter = w * h
        overlap = inter / np.maximum(area[i] + area[rest] - inter, 1e-9)
        order = rest[overlap <= iou]
    return kept


def load_bgr(path, background=None):
    """An image file as 8-bit BGR. With `background` (RGB 0-255), an alpha channel is composited over it, and a view
    of `g2p render` (VIEW_rgb.png beside VIEW_faceid.png, where 0 is background) gets it where no face was drawn;
    without, the alpha is dropped."""
    import cv2
    img = cv2.imread(path, cv2.IMREAD_UNCHANGED)
    if img is None:
        raise ValueError(f"{path}: not an image OpenCV reads")
    if img.dtype != np.uint8:
        img = (img / (65535.0 if img.dtype == np.uint16 else 1.0) * 255).clip(0, 255).astype(np.uint8)
    if img.ndim == 2:
        img = cv2.cvtColor(img, cv2.COLOR_GRAY2BGR)
    if img.shape[2] == 4:
        alpha = img[:, :, 3:4].astype(np.float32) / 255
        bg = np.float32(background[::-1] if background is not None else [0, 0, 0])
        colour = img[:, :, :3].astype(np.float32)
        img = (colour * alpha + bg * (1 - alpha)).round().astype(np.uint8) if background is not None \
            else img[:, :, :3].copy()
    faceid = path[:-len("_rgb.png")] + "_faceid.png" if path.endswith("_rgb.png") else None
    if background is not None and faceid and os.path.exists(faceid):
        ids = cv2.imread(faceid, cv2.IMREAD_COLOR)
        if ids is not None and ids.shape[:2] == img.shape[:2]:
            img = img.copy()
            img[(ids == 0).all(2)] = background[::-1]
    return img


def draw(bgr, found, path):
    import cv2
    img = bgr.copy()
    for name, score, (x1, y1, x2, y2) in found:
        cv2.rectangle(img, (int(x1), int(y1)), (int(x2), int(y2)), (0, 0, 255), 2)
        cv2.putText(img, f"{name} {score:.2f}", (int(x1) + 2, int(y1) + 14), cv2.FONT_HERSHEY_SIMPLEX, 0.5,
                    (0, 0, 255), 1)
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    cv2.imwrite(path, img)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("images", nargs="+")
    ap.add_argument("--card", default=CARD)
    ap.add_argument("--onnx", help="the ONNX file (default: the card's, beside it)")
    ap.add_argument("--threshold", type=float, help="score threshold (default: the card's)")
    ap.add_argument("--background", help="R,G,B (0-255): the background of views of g2p render (from their faceid "
                    "image) or of images with alpha; 128,128,128 detects best on our renders")
    ap.add_argument("--top", type=int, default=3, help="detections / voted classes to print")
    ap.add_argument("--json", help="write the detections and the vote here")
    ap.add_argument("--draw", metavar="DIR", help="write each image with its detections drawn into DIR")
    a = ap.parse_args()
    background = [int(v) for v in a.background.split(",")] if a.background else None
    det = Detector(a.card, a.onnx)
    ballots, report = [], {"views": {}}
    for path in a.images:
        bgr = load_bgr(path, background)
        found, raw = det.detect(bgr, a.threshold)
        if a.draw:
            draw(bgr, found, os.path.join(a.draw, "_".join(os.path.normpath(path).split(os.sep)[-2:])))
        ballots.append(det.best_per_class(raw))
        report["views"][path] = [{"class": c, "score": s, "box": [float(v) for v in b]} for c, s, b in found]
        shown = ", ".join(f"{c} {s:.2f}" for c, s, _ in found[:a.top]) or "-"
        print(f"{path}: {shown}")
    vote = np.mean(ballots, 0)
    order = np.argsort(-vote)[:a.top]
    report["vote"] = [{"class": det.classes[i], "score": float(vote[i])} for i in order]
    print(f"vote over {len(ballots)} view(s): " + ", ".join(f"{det.classes[i]} {vote[i]:.2f}" for i in order))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(report, f, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
