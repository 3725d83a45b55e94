#!/usr/bin/python3
"""Paired NanoDet (shipped ONNX) vs CenterNet (our ONNX) on the same renders of the validation models.

    /usr/bin/python3 tools/training/centernet/compare_detectors.py --centernet centernet.onnx [--res 416] --out F.json

An experiment for issue #48 (docs/accuracy.md): CenterNet from export_centernet.py beside the shipped NanoDet-g, on
the validation models with names removed. Needs the Python module built (build/python) and data/sh3d.

Views: 8 turntable views, elevation 15 deg (as detector_identifier.cpp), 512x512, background grey 128 (rendered so,
and background pixels by face ID repainted 128 anyway), through libg2p's Python bindings. Each detector gets the same
image resized (bilinear, stretched) to its input. Vote as detector_identifier.cpp: per view and class the best score
of a detection whose box has IoU >= 0.3 with the object's pixel box; confidence = mean over the best half of the
views; classes < 0.3 dropped; the top class mapping to a kind (objects.json 'coco') is the answer.
"""
import argparse
import json
import os
import subprocess
import sys
import time

import cv2
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "build", "python"))
import g2p  # noqa: E402

G2P = ROOT + "/build/bin/g2p"
CENTERNET_ONNX = ""
MIN_IOU, MIN_SCORE = 0.3, 0.3
TRUTH = {"Knife stand": "", "Wall type B plug": "", "Square type B plug": "", "Double window 4 panes": "window",
         "Indoor bike": "exercise bike", "Rigged fan": "fan", "Yamaha YZR R6": "motorcycle",
         "Toilets unit": "toilet", "Small oven": "oven"}  # score_identify_val.py's TRUTH

card = json.load(open(ROOT + "/libg2p/data/models/g2p-objects-nanodet.json"))
COCO = card["classes"]
KIND_OF = {k["coco"]: k["name"] for k in json.load(open(ROOT + "/libg2p/data/objects.json"))["kinds"]
           if k.get("coco")}


def iou(a, b):
    ix = max(0.0, min(a[2], b[2]) - max(a[0], b[0]))
    iy = max(0.0, min(a[3], b[3]) - max(a[1], b[1]))
    inter = ix * iy
    u = (a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - inter
    return inter / u if u > 0 else 0.0


class NanoDet:
    def __init__(self):
        self.net = cv2.dnn.readNetFromONNX(ROOT + "/libg2p/data/models/" + card["model"])
        self.W, self.H = card["input"]["width"], card["input"]["height"]
        self.mean, self.std = np.array(card["input"]["mean"]), np.array(card["input"]["std"])
        self.outs = card["outputs"]
        self.bins = card["decode"]["reg_max"] + 1

    def best(self, rgb, obj):
        h, w = rgb.shape[:2]
        x = cv2.resize(rgb, (self.W, self.H), interpolation=cv2.INTER_LINEAR)[:, :, ::-1].astype(np.float32)
        x = (x - self.mean) / self.std
        self.net.setInput(cv2.dnn.blobFromImage(x.astype(np.float32)))
        names = [o["name"] for o in self.outs]
        outs = dict(zip(names, self.net.forward(names)))
        best = np.zeros(80)
        sx, sy = w / self.W, h / self.H
        for o in self.outs:
            if not o["name"].startswith("scores"):
                continue
            s = o["stride"]
            sc = outs[o["name"]].reshape(-1, 80)
            bx = outs["boxes_stride%d" % s].reshape(-1, 4, self.bins)
            gw = self.W // s
            for i in np.nonzero(sc.max(1) >= MIN_SCORE)[0]:
                cx, cy = (i % gw + 0.5) * s, (i // gw + 0.5) * s
                p = np.exp(bx[i] - bx[i].max(1, keepdims=True))
                d = s * (p * np.arange(self.bins)).sum(1) / p.sum(1)
                box = (np.clip(cx - d[0], 0, self.W) * sx, np.clip(cy - d[1], 0, self.H) * sy,
                       np.clip(cx + d[2], 0, self.W) * sx, np.clip(cy + d[3], 0, self.H) * sy)
                if iou(box, obj) >= MIN_IOU:
                    best = np.maximum(best, sc[i])
        return best


class CenterNetDet:
    SIZE = 512

    def __init__(self):
        from export_centernet import decode_centernet
        self.decode = decode_centernet
        self.net = cv2.dnn.readNetFromONNX(CENTERNET_ONNX)

    def best(self, rgb, obj):
        h, w = rgb.shape[:2]
        x = cv2.resize(rgb, (self.SIZE, self.SIZE), interpolation=cv2.INTER_LINEAR).astype(np.float32)  # RGB 0-255
        self.net.setInput(np.ascontiguousarray(x.transpose(2, 0, 1))[None])
        hm, wh = self.net.forward(["keypoints", "wh"])
        det = self.decode(hm[0], wh[0])  # the graph's own top-100 peaks
        best = np.zeros(80)
        sx, sy = w / self.SIZE, h / self.SIZE
        for x1, y1, x2, y2, score, c in det:
            box = (np.clip(x1, 0, self.SIZE) * sx, np.clip(y1, 0, self.SIZE) * sy,
                   np.clip(x2, 0, self.SIZE) * sx, np.clip(y2, 0, self.SIZE) * sy)
            if iou(box, obj) >= MIN_IOU:
                best[int(c)] = max(best[int(c)], score)
        return best


def vote(per_view):
    """per_view: [views][80] -> [(confidence, coco)] sorted, >= MIN_SCORE."""
    b = np.sort(np.array(per_view), 0)[::-1]
    half = (len(per_view) + 1) // 2
    conf = b[:half].mean(0)
    return conf


def answer(conf):
    order = np.argsort(-conf)
    for c in order:
        if conf[c] < MIN_SCORE:
            break
        if COCO[c] in KIND_OF:
            return KIND_OF[COCO[c]], float(conf[c]), COCO[c]
    return "unknown", 0.0, ""


def g2p_json(args):
    d = subprocess.run([G2P, "identify"] + args + ["--json"], capture_output=True, text=True)
    return json.loads(d.stdout) if d.returncode == 0 else None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--centernet", required=True, help="the ONNX file export_centernet.py wrote")
    ap.add_argument("--out", default="results.json")
    ap.add_argument("--limit", type=int, default=0)
    ap.add_argument("--res", type=int, default=512)
    ap.add_argument("--save-views", default="", help="also write every view as JPEG here")
    a = ap.parse_args()
    global CENTERNET_ONNX
    CENTERNET_ONNX = a.centernet
    models = json.load(open(ROOT + "/data/mass-ranges/val.json"))["models"]
    nd, cn = NanoDet(), CenterNetDet()
    renderer = g2p.make_renderer("embree")
    vo = g2p.ViewOptions(num_views=8, layout=g2p.ViewLayout.TURNTABLE, elevation_deg=15.0, width=a.res, height=a.res)
    ro = g2p.RenderOptions(material_buffers=False, geometry_buffers=False, background=(128, 128, 128))
    rows, times = [], {"render": [], "nanodet": [], "centernet": []}
    for key in sorted(models):
        name = models[key]["name"]
        path = os.path.join(ROOT, "data", "sh3d", key)
        truth = TRUTH.get(name)
        if truth is None:
            t = g2p_json([path, "--object", name, "--identifier", "object"])
            truth = t["kind"] if t else None
        if not truth or truth == "unknown":
            continue
        t0 = time.time()
        model = g2p.load_model(path)
        model.anonymize_names()
        views = g2p.render_views(renderer, model, g2p.make_views(model.mesh, vo), ro)
        times["render"].append(time.time() - t0)
        pv = {"nanodet": [], "centernet": []}
        for vi, v in enumerate(views):
            rgb = np.array(v.rgb).copy()
            fid = np.array(v.face_id)
            ys, xs = np.nonzero(fid >= 0)
            if len(xs) == 0:
                continue
            obj = (xs.min(), ys.min(), xs.max() + 1, ys.max() + 1)
            rgb[fid < 0] = 128
            if a.save_views:
                os.makedirs(a.save_views, exist_ok=True)
                cv2.imwrite(f"{a.save_views}/{len(rows):02d}_{vi}.jpg", rgb[:, :, ::-1])
            for nm, det in (("nanodet", nd), ("centernet", cn)):
                t1 = time.time()
                pv[nm].append(det.best(rgb, obj))
                times[nm].append(time.time() - t1)
        cn_conf, nd_conf = vote(pv["centernet"]), vote(pv["nanodet"])
        both = 1 - (1 - nd_conf) * (1 - cn_conf)
        row = {"key": key, "name": name, "truth": truth}
        for nm, conf in (("nanodet", nd_conf), ("centernet", cn_conf), ("both", both)):
            kind, c, coco = answer(conf)
            top3 = [(COCO[i], round(float(conf[i]), 3)) for i in np.argsort(-conf)[:3]]
            row[nm] = {"kind": kind, "confidence": c, "coco": coco, "ok": kind == truth, "top3": top3}
        rows.append(row)
        print("%-26s %-14s | nd %-12s %.2f %s | cn %-12s %.2f %s | both %-12s %.2f %s" % (
            name[:26], truth[:14], *[v for nm in ("nanodet", "centernet", "both") for v in (
                row[nm]["kind"][:12], row[nm]["confidence"], "ok" if row[nm]["ok"] else "--")]), flush=True)
        if a.limit and len(rows) >= a.limit:
            break
    summ = {"models": len(rows)}
    for nm in ("nanodet", "centernet", "both"):
        conf_rows = [r for r in rows if r[nm]["confidence"] >= 0.6]
        summ[nm] = {"top1": sum(r[nm]["ok"] for r in rows),
                    "named": sum(r[nm]["kind"] != "unknown" for r in rows),
                    "named_ge_0.6": len(conf_rows), "right_ge_0.6": sum(r[nm]["ok"] for r in conf_rows)}
    summ["only_nanodet_right"] = [r["name"] for r in rows if r["nanodet"]["ok"] and not r["centernet"]["ok"]]
    summ["only_centernet_right"] = [r["name"] for r in rows if r["centernet"]["ok"] and not r["nanodet"]["ok"]]
    summ["seconds_per_model_8_views"] = {k: round(8 * float(np.mean(v)) if k != "render" else float(np.mean(v)), 3)
                                         for k, v in times.items() if v}
    print(json.dumps(summ, indent=1))
    json.dump({"summary": summ, "rows": rows}, open(a.out, "w"), indent=1)


if __name__ == "__main__":
    main()
