"""Minimal reader for the single-material GLB files of the generated test set (#31).

Reads what image-to-3D generators write (TRELLIS, Hunyuan3D-2, SF3D, SPAR3D, TripoSR through
trimesh): triangle primitives, node transforms, TEXCOORD_0 with an embedded base-colour image,
or COLOR_0. Face order is the order of the primitives' index buffers, which is the order of
`source_face` in `g2p run`'s faces.csv (checked per model by score.py through the face areas).
numpy and Pillow only.
"""
import io
import json
import struct

import numpy as np
from PIL import Image

_DTYPES = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32,
           5126: np.float32}
_WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


def _accessor(doc, binary, index):
    acc = doc["accessors"][index]
    view = doc["bufferViews"][acc["bufferView"]]
    dtype = np.dtype(_DTYPES[acc["componentType"]])
    width = _WIDTH[acc["type"]]
    start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    stride = view.get("byteStride", 0) or dtype.itemsize * width
    count = acc["count"]
    raw = np.frombuffer(binary, dtype=np.uint8, count=stride * (count - 1) + dtype.itemsize * width,
                        offset=start)
    rows = np.lib.stride_tricks.as_strided(raw, shape=(count, dtype.itemsize * width),
                                           strides=(stride, 1))
    out = np.ascontiguousarray(rows).view(dtype).reshape(count, width).astype(np.float64)
    if acc.get("normalized") and dtype.kind in "ui":
        out /= np.iinfo(dtype).max
    return out


def _node_matrix(node):
    if "matrix" in node:
        return np.array(node["matrix"], dtype=np.float64).reshape(4, 4).T
    m = np.eye(4)
    x, y, z, w = node.get("rotation", [0, 0, 0, 1])
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    m[:3, :3] = r * np.array(node.get("scale", [1, 1, 1]))[None, :]
    m[:3, 3] = node.get("translation", [0, 0, 0])
    return m


class Model:
    """Triangles of a GLB in scene space: positions (V,3), faces (F,3), per-face base colour."""

    def __init__(self, path):
        data = open(path, "rb").read()
        magic, _, _ = struct.unpack("<4sII", data[:12])
        if magic != b"glTF":
            raise ValueError(f"{path}: not a binary glTF")
        offset, doc, binary = 12, None, b""
        while offset < len(data):
            length, kind = struct.unpack("<II", data[offset:offset + 8])
            chunk = data[offset + 8:offset + 8 + length]
            if kind == 0x4E4F534A:
                doc = json.loads(chunk)
            elif kind == 0x004E4942:
                binary = chunk
            offset += 8 + length
        self.doc = doc
        positions, faces, colours = [], [], []
        base = 0
        scene = doc["scenes"][doc.get("scene", 0)]

        def visit(index, parent):
            nonlocal base
            node = doc["nodes"][index]
            world = parent @ _node_matrix(node)
            if "mesh" in node:
                for prim in doc["meshes"][node["mesh"]]["primitives"]:
                    if prim.get("mode", 4) != 4:
                        continue
                    p = _accessor(doc, binary, prim["attributes"]["POSITION"])
                    p = (np.c_[p, np.ones(len(p))] @ world.T)[:, :3]
                    if "indices" in prim:
                        f = _accessor(doc, binary, prim["indices"]).astype(np.int64).reshape(-1, 3)
                    else:
                        f = np.arange(len(p)).reshape(-1, 3)
                    colours.append(self._face_colours(doc, binary, prim, f))
                    positions.append(p)
                    faces.append(f + base)
                    base += len(p)
            for child in node.get("children", []):
                visit(child, world)

        for root in scene["nodes"]:
            visit(root, np.eye(4))
        self.positions = np.concatenate(positions)
        self.faces = np.concatenate(faces)
        self.face_rgb = np.concatenate(colours)  # 0..1 as stored (sRGB texels), (F,3)
        self.up_axis = 1  # glTF: +y is up

    def _face_colours(self, doc, binary, prim, f):
        """Base colour at each face: the texel at the face's UV centroid times the factor,
        else the mean vertex colour, else the factor."""
        factor = np.ones(4)
        texture = None
        if "material" in prim:
            pbr = doc["materials"][prim["material"]].get("pbrMetallicRoughness", {})
            factor = np.array(pbr.get("baseColorFactor", [1, 1, 1, 1]))
            if "baseColorTexture" in pbr and "TEXCOORD_0" in prim["attributes"]:
                image = doc["images"][doc["textures"][pbr["baseColorTexture"]["index"]]["source"]]
                view = doc["bufferViews"][image["bufferView"]]
                start = view.get("byteOffset", 0)
                blob = binary[start:start + view["byteLength"]]
                texture = np.asarray(Image.open(io.BytesIO(blob)).convert("RGB"), dtype=np.float64) / 255
        if texture is not None:
            uv = _accessor(doc, binary, prim["attributes"]["TEXCOORD_0"])
            c = uv[f].mean(axis=1)
            h, w = texture.shape[:2]
            px = np.clip((c[:, 0] % 1.0) * w, 0, w - 1).astype(int)
            py = np.clip((c[:, 1] % 1.0) * h, 0, h - 1).astype(int)
            return texture[py, px] * factor[:3]
        if "COLOR_0" in prim["attributes"]:
            col = _accessor(doc, binary, prim["attributes"]["COLOR_0"])[:, :3]
            return col[f].mean(axis=1) * factor[:3]
        return np.tile(factor[:3], (len(f), 1))

    def face_areas(self):
        p = self.positions[self.faces]
        return 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)

    def components(self):
        """Connected component of every face (vertices welded by position), 0 = most faces."""
        _, weld = np.unique(np.round(self.positions, 6), axis=0, return_inverse=True)
        weld = weld.reshape(-1)
        parent = np.arange(weld.max() + 1)

        def find(a):
            while parent[a] != a:
                parent[a] = parent[parent[a]]
                a = parent[a]
            return a

        f = weld[self.faces]
        for a, b in ((0, 1), (1, 2)):
            for u, v in zip(f[:, a], f[:, b]):
                ru, rv = find(u), find(v)
                if ru != rv:
                    parent[ru] = rv
        roots = np.array([find(v) for v in f[:, 0]])
        ids, inverse, counts = np.unique(roots, return_inverse=True, return_counts=True)
        rank = np.empty(len(ids), dtype=int)
        rank[np.argsort(-counts, kind="stable")] = np.arange(len(ids))
        return rank[inverse]
