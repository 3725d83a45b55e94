"""What the add-on does that is not Blender's interface: the g2p module, the
run and its result as plain data. Imports no bpy, so it is tested with plain
Python (and used by the operators inside Blender)."""

import importlib
import json
import sys
import threading
import uuid

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


class ResultCache:
    """The last few runs' results, by a key the scene keeps on the body object,
    so that a correction resumes its run instead of starting over. Blender
    cannot store them in the .blend file; after a reload a correction reruns
    the pipeline from the source objects, with the same outcome."""

    def __init__(self, size=4):
        self.size = size
        self._items = {}  # key -> result, oldest first

    def put(self, result):
        key = uuid.uuid4().hex
        self._items[key] = result
        while len(self._items) > self.size:
            del self._items[next(iter(self._items))]
        return key

    def get(self, key):
        return self._items.get(key)


class Run:
    """A pipeline run on a worker thread: progress and cancellation through
    g2p.RunContext, the result or the error when it is done. With `previous`
    (an earlier run's result) it resumes that run with options.overrides: the
    library goes back as far as they change (classes: complete; properties:
    properties) and reuses the views, labels and parts before that."""

    def __init__(self, g2p, model, options, previous=None):
        self.g2p = g2p
        self.model = model
        self.options = options
        self.previous = previous
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
            pipeline = self.g2p.Pipeline(self.options)
            if self.previous is not None:
                self.result = pipeline.resume(self.previous, self.g2p.Stage.EXPORT, context=self._context)
            else:
                self.result = pipeline.run(self.model, context=self._context)
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
