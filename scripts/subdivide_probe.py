#!/usr/bin/env python3
"""The large-input probe of docs/performance.md (#50): a GLB with every triangle
of a GLB model split 4-to-1 LEVELS times (SheenChair, 39,936 triangles, three
times: 2,555,904). Keeps the nodes (transforms), each primitive's material index
and the materials in their order with their names and factors (labels.json keys
materials by index, so --truth still applies), interpolates POSITION, NORMAL and
TEXCOORD_0 (edge midpoints shared by the two triangles of an edge), drops
textures. Needs numpy.

    /usr/bin/python3 scripts/subdivide_probe.py ../shared/assets/SheenChair/SheenChair.glb /tmp/SheenChair_l3.glb 3
"""
import json, struct, sys
import numpy as np

CT = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
NC = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}

def read_glb(path):
    d = open(path, "rb").read()
    assert d[:4] == b"glTF"
    off, j, binc = 12, None, None
    while off < len(d):
        ln, ty = struct.unpack("<II", d[off:off + 8])
        chunk = d[off + 8:off + 8 + ln]
        if ty == 0x4E4F534A: j = json.loads(chunk)
        elif ty == 0x004E4942: binc = chunk
        off += 8 + ln
    return j, binc

def accessor(j, b, i):
    a = j["accessors"][i]
    assert "sparse" not in a
    bv = j["bufferViews"][a["bufferView"]]
    dt = np.dtype(CT[a["componentType"]]); n = NC[a["type"]]
    start = bv.get("byteOffset", 0) + a.get("byteOffset", 0)
    stride = bv.get("byteStride", dt.itemsize * n)
    raw = np.frombuffer(b, np.uint8, count=stride * (a["count"] - 1) + dt.itemsize * n, offset=start)
    out = np.lib.stride_tricks.as_strided(raw, (a["count"], dt.itemsize * n), (stride, 1)).copy()
    out = out.view(dt).reshape(a["count"], n)
    if a.get("normalized"):
        out = out.astype(np.float64) / np.iinfo(dt).max
    return out

def subdivide(tris, attrs):
    """One 4-to-1 split; midpoints shared between the two triangles of an edge."""
    nv = len(next(iter(attrs.values())))
    e = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    e.sort(axis=1)
    uniq, inv = np.unique(e, axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    mid = nv + inv.reshape(3, -1).T  # per triangle: m01, m12, m20
    new = {}
    for k, v in attrs.items():
        m = (v[uniq[:, 0]].astype(np.float64) + v[uniq[:, 1]]) / 2
        if k == "NORMAL":
            m /= np.maximum(np.linalg.norm(m, axis=1, keepdims=True), 1e-12)
        new[k] = np.concatenate([v, m.astype(np.float32)])
    a, b_, c = tris[:, 0], tris[:, 1], tris[:, 2]
    m01, m12, m20 = mid[:, 0], mid[:, 1], mid[:, 2]
    t = np.stack([np.stack([a, m01, m20], 1), np.stack([m01, b_, m12], 1),
                  np.stack([m20, m12, c], 1), np.stack([m01, m12, m20], 1)], 1).reshape(-1, 3)
    return t, new

def main():
    src, dst = sys.argv[1], sys.argv[2]
    levels = int(sys.argv[3]) if len(sys.argv) > 3 else 3
    j, b = read_glb(src)
    blob = bytearray(); views = []; accs = []; meshes = []; total = 0

    def add(arr, target, kind):
        arr = np.ascontiguousarray(arr)
        while len(blob) % 4: blob.append(0)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": arr.nbytes, "target": target})
        blob.extend(arr.tobytes())
        a = {"bufferView": len(views) - 1, "count": len(arr),
             "componentType": 5125 if arr.dtype == np.uint32 else 5126,
             "type": "SCALAR" if arr.ndim == 1 else {2: "VEC2", 3: "VEC3"}[arr.shape[1]]}
        if kind == "POSITION":
            a["min"] = arr.min(0).tolist(); a["max"] = arr.max(0).tolist()
        accs.append(a)
        return len(accs) - 1

    for m in j["meshes"]:
        prims = []
        for p in m["primitives"]:
            assert p.get("mode", 4) == 4
            tris = accessor(j, b, p["indices"]).reshape(-1, 3).astype(np.int64)
            attrs = {k: accessor(j, b, p["attributes"][k]).astype(np.float32)
                     for k in ("POSITION", "NORMAL", "TEXCOORD_0") if k in p["attributes"]}
            for _ in range(levels):
                tris, attrs = subdivide(tris, attrs)
            total += len(tris)
            prim = {"attributes": {k: add(v, 34962, k) for k, v in attrs.items()},
                   "indices": add(tris.astype(np.uint32).reshape(-1), 34963, "idx")}
            if "material" in p: prim["material"] = p["material"]
            prims.append(prim)
        mm = {"primitives": prims}
        if "name" in m: mm["name"] = m["name"]
        meshes.append(mm)

    mats = []
    for mat in j.get("materials", []):
        pbr = mat.get("pbrMetallicRoughness", {})
        nm = {"name": mat.get("name", ""), "pbrMetallicRoughness": {
            k: pbr[k] for k in ("baseColorFactor", "metallicFactor", "roughnessFactor") if k in pbr}}
        mats.append(nm)
    out = {"asset": {"version": "2.0", "generator": "subdivide_probe.py"},
           "scene": j.get("scene", 0), "scenes": j["scenes"], "nodes": j["nodes"],
           "meshes": meshes, "materials": mats, "accessors": accs, "bufferViews": views,
           "buffers": [{"byteLength": len(blob)}]}
    while len(blob) % 4: blob.append(0)
    js = json.dumps(out, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    with open(dst, "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(js) + 8 + len(blob)))
        f.write(struct.pack("<II", len(js), 0x4E4F534A)); f.write(js)
        f.write(struct.pack("<II", len(blob), 0x004E4942)); f.write(bytes(blob))
    print(f"{dst}: {total} triangles, {len(blob)} bytes of buffer")

if __name__ == "__main__":
    main()
