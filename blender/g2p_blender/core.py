"""What the add-on does that is not Blender's interface: the g2p module, the
run and its result as plain data. Imports no bpy, so it is tested with plain
Python (and used by the operators inside Blender)."""

import importlib
import json
import struct
import sys
import threading

import numpy as np


class ModuleMissing(RuntimeError):
    """`import g2p` failed; the message says where it looked."""


def import_g2p(extra_path=""):
    """The g2p module, looking first in extra_path (the add-on preference)
    when given. Raises ModuleMissing with a message for the user."""
    if extra_path and extra_path not in sys.path:
        sys.path.insert(0, extra_path)
    try:
        return importlib.import_module("g2p")
    except ImportError as e:
        where = f" or in {extra_path!r}" if extra_path else ""
        raise ModuleMissing(
            f"cannot import the g2p Python module ({e}): it was not found on Blender's Python path{where}. "
            "Build libg2p's Python bindings for this Blender's Python "
            f"({sys.version.split()[0]}) and set the module folder in the add-on's preferences "
            "(the folder holding g2p.cpython-*.so, e.g. build/python)") from e


def library_defaults(g2p):
    """The library's own defaults for the options the panel offers."""
    options = g2p.PipelineOptions()
    return {
        "segmenter": options.segmenter.name,
        "segmenters": list(g2p.segmenter_names()),
        "object": options.object,
        "max_hulls": options.decompose.max_hulls,
    }


def pipeline_options(g2p, segmenter="", object_words="", max_hulls=0, overrides=None):
    """PipelineOptions with only what the user chose set; '' and 0 keep the
    library's value. No files are written (formats = [])."""
    options = g2p.PipelineOptions()
    options.formats = []
    if segmenter:
        options.segmenter = g2p.BackendChoice(segmenter)
    if object_words:
        options.object = object_words
    if max_hulls > 0:
        options.decompose.max_hulls = max_hulls
    if overrides is not None:
        options.overrides = overrides
    return options


class MeshInput:
    """The selected objects' geometry as one model: world-space positions in
    metres (+Z up, as Blender and g2p), triangles, a material per face.

    The model reaches g2p as a GLB built in memory (g2p.load_model_from_memory),
    not Model.from_arrays: the segmenter reads the materials' names, base
    colours and metallic/roughness, which from_arrays cannot carry, and the
    import applies the real size (height_m, longest_side_m) as `g2p run` does."""

    def __init__(self, name="object"):
        self.name = name
        self._positions = []
        self._triangles = []
        self._face_materials = []
        self._uvs = []  # per object: (N, 2) in Blender's convention (v up), or None
        self.materials = []  # dicts: name, base_color (linear RGBA), metallic, roughness
        self._material_index = {}  # material key -> index into materials
        self._vertices = 0

    def add(self, positions, triangles, slot_materials, triangle_slots, uvs=None):
        """One object's mesh: positions (N, 3), triangles (M, 3), its slots'
        materials as (key, dict) or None per slot, each triangle's slot, and
        optionally per-vertex texture coordinates (N, 2), v up as in Blender.
        A material dict holds name, base_color (linear RGBA), metallic,
        roughness and base_color_image: (bytes, 'image/png' or 'image/jpeg')."""
        positions = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
        triangles = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
        triangle_slots = np.asarray(triangle_slots, dtype=np.int64).reshape(-1)
        slot_to_material = []
        for slot in slot_materials or [None]:
            key, material = slot if slot is not None else (None, {})
            if key not in self._material_index:
                self._material_index[key] = len(self.materials)
                material = dict(material)
                material.setdefault("name", "material_" + str(len(self.materials)))
                self.materials.append(material)
            slot_to_material.append(self._material_index[key])
        slots = np.clip(triangle_slots, 0, len(slot_to_material) - 1)
        self._positions.append(positions)
        self._uvs.append(None if uvs is None else np.asarray(uvs, dtype=np.float64).reshape(-1, 2))
        self._triangles.append(triangles + self._vertices)
        self._face_materials.append(np.asarray(slot_to_material, dtype=np.int32)[slots])
        self._vertices += len(positions)

    def arrays(self):
        if not self._triangles or not sum(len(t) for t in self._triangles):
            raise ValueError("no triangles in the selected objects")
        return (np.concatenate(self._positions), np.concatenate(self._triangles).astype(np.uint32),
                np.concatenate(self._face_materials))

    def glb(self):
        """The model as GLB bytes: one mesh, a primitive per material sharing
        one vertex buffer, +Y up as glTF says (g2p turns it back to +Z)."""
        positions, triangles, face_materials = self.arrays()
        gltf_positions = np.ascontiguousarray(positions[:, [0, 2, 1]] * [1, 1, -1], dtype=np.float32)
        blob = bytearray()
        views, accessors = [], []

        def add_view(data, **extra):
            views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data), **extra})
            blob.extend(data)
            blob.extend(b"\0" * (-len(blob) % 4))
            return len(views) - 1

        accessors.append({"bufferView": add_view(gltf_positions.tobytes(), target=34962), "componentType": 5126,
                          "count": len(gltf_positions), "type": "VEC3",
                          "min": gltf_positions.min(axis=0).tolist(), "max": gltf_positions.max(axis=0).tolist()})
        attributes = {"POSITION": 0}
        if any(uv is not None for uv in self._uvs):
            uvs = np.concatenate([uv if uv is not None else np.zeros((len(p), 2))
                                  for uv, p in zip(self._uvs, self._positions)])
            gltf_uvs = np.ascontiguousarray(np.stack([uvs[:, 0], 1.0 - uvs[:, 1]], axis=1), dtype=np.float32)
            accessors.append({"bufferView": add_view(gltf_uvs.tobytes(), target=34962), "componentType": 5126,
                              "count": len(gltf_uvs), "type": "VEC2"})
            attributes["TEXCOORD_0"] = len(accessors) - 1
        primitives = []
        for m in range(len(self.materials)):
            indices = np.ascontiguousarray(triangles[face_materials == m], dtype=np.uint32).tobytes()
            if not indices:
                continue
            accessors.append({"bufferView": add_view(indices, target=34963), "componentType": 5125,
                              "count": len(indices) // 4, "type": "SCALAR"})
            primitives.append({"attributes": attributes, "indices": len(accessors) - 1, "material": m})
        materials, images = [], []
        for m in self.materials:
            pbr = {"baseColorFactor": [float(c) for c in m.get("base_color", (0.8, 0.8, 0.8, 1.0))]}
            for key, gltf_key in (("metallic", "metallicFactor"), ("roughness", "roughnessFactor")):
                if key in m:
                    pbr[gltf_key] = float(m[key])
            if m.get("base_color_image") and "TEXCOORD_0" in attributes:
                data, mime = m["base_color_image"]
                images.append({"bufferView": add_view(data), "mimeType": mime})
                pbr["baseColorTexture"] = {"index": len(images) - 1}
            materials.append({"name": m["name"], "pbrMetallicRoughness": pbr})
        document = {"asset": {"version": "2.0", "generator": "g2p Blender add-on"}, "scene": 0,
                    "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0, "name": self.name}],
                    "meshes": [{"name": self.name, "primitives": primitives}], "materials": materials,
                    "accessors": accessors, "bufferViews": views, "buffers": [{"byteLength": len(blob)}]}
        if images:
            document["images"] = images
            document["textures"] = [{"source": i} for i in range(len(images))]
        text = json.dumps(document).encode()
        text += b" " * (-len(text) % 4)
        chunks = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(blob), 0x004E4942) + blob
        return bytes(struct.pack("<III", 0x46546C67, 2, 12 + len(chunks)) + chunks)

    def model(self, g2p, height_m=0.0, longest_side_m=0.0):
        return g2p.load_model_from_memory(self.glb(), "glb", height_m=height_m, longest_side_m=longest_side_m)


def split_by_uv(triangles, corner_uvs):
    """Per-vertex texture coordinates from per-corner ones (Blender's loops):
    a vertex with several UVs (a seam) becomes several vertices, as in any
    glTF. Returns (source vertex per new vertex, new triangles, uvs)."""
    corners = np.concatenate([triangles.reshape(-1, 1).astype(np.float64), corner_uvs.reshape(-1, 2)], axis=1)
    keys, inverse = np.unique(corners, axis=0, return_inverse=True)
    return keys[:, 0].astype(np.int64), inverse.reshape(-1, 3), keys[:, 1:]


def correction_overrides(g2p, corrections, table, faces_total):
    """g2p.Overrides from the add-on's corrections: dicts with 'faces' (input
    face indices) and any of 'class', 'structure', 'density_kg_m3'. Face
    selections, not part numbers, so they keep their meaning as parts re-form."""
    entries = []
    for c in corrections:
        entry = {"faces": [int(f) for f in c["faces"]]}
        entry.update({k: c[k] for k in ("class", "structure", "density_kg_m3") if k in c})
        entries.append(entry)
    text = json.dumps({"format": "g2p-overrides", "version": 1, "faces_total": faces_total, "overrides": entries})
    return g2p.parse_overrides(text, table, "Blender corrections")


def part_records(result):
    """One dict per part of a run: what the scene needs (closed mesh, hulls,
    class colour, properties), in the run's frame (world space here)."""
    table = result.table
    closed = {c.part: c.mesh for c in result.completion.parts}
    faces = {p["index"]: p["faces"] for p in result.parts}
    records = []
    for p in result.properties:
        i = p["part"]
        label = p["label"]
        colour = table[label].color if 0 <= label < len(table) else (128, 128, 128)
        mesh = closed.get(i)
        records.append({
            "part": i,
            "class": p["class"] or "unknown",
            "colour_srgb": tuple(c / 255.0 for c in colour),
            "structure": p["structure"],
            "wall_thickness_m": p["wall_thickness_m"],
            "density_kg_m3": p["density_kg_m3"],
            "mass_kg": p["mass_kg"],
            "center_of_mass": np.asarray(p["center_of_mass"], dtype=np.float64),
            "friction": p["friction_dynamic"],
            "restitution": p["restitution"],
            "area_m2": p["area_m2"],
            "faces": faces.get(i, np.zeros(0, np.int32)),
            "positions": mesh.positions if mesh is not None else np.zeros((0, 3)),
            "triangles": mesh.triangles if mesh is not None else np.zeros((0, 3), np.int32),
            "hulls": [(h.positions, h.triangles) for h in result.collision[i].hulls] if i < len(result.collision) else [],
        })
    return records


def contact_settings(records):
    """One friction and restitution for the whole body (Blender gives a rigid
    body one of each): the parts' values weighted by their surface area."""
    area = sum(r["area_m2"] for r in records)
    if area <= 0:
        return None, None
    friction = sum(r["friction"] * r["area_m2"] for r in records) / area
    restitution = sum(r["restitution"] * r["area_m2"] for r in records) / area
    return friction, restitution


class Run:
    """A pipeline run on a worker thread: progress and cancellation through
    g2p.RunContext, the result or the error when it is done."""

    def __init__(self, g2p, model, options):
        self.g2p = g2p
        self.model = model
        self.options = options
        self.progress = 0.0
        self.message = "starting"
        self.result = None
        self.error = None
        self._context = g2p.RunContext(progress=self._on_progress)
        self._thread = None

    def _on_progress(self, p):
        self.progress = p.overall
        self.message = f"{p.stage_name}: {p.message}" if p.message else p.stage_name
        return True

    def run(self):
        """Runs on this thread (the tests, Blender in background mode)."""
        try:
            self.result = self.g2p.Pipeline(self.options).run(self.model, context=self._context)
        except Exception as e:  # a g2p.Error, or what a stage raised: shown to the user
            self.error = e

    def start(self):
        self._thread = threading.Thread(target=self.run, name="g2p run", daemon=True)
        self._thread.start()

    def cancel(self):
        self._context.cancel()

    @property
    def done(self):
        return self._thread is None or not self._thread.is_alive()

    @property
    def cancelled(self):
        return isinstance(self.error, self.g2p.Cancelled)
