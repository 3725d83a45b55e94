"""The `g2p` Python module on real data: the hammer (examples/data/hammer.obj,
a wooden handle and a steel head) and a shared asset. Runs under unittest and
pytest; ctest sets PYTHONPATH to the built module and G2P_SHARED_ASSETS /
G2P_HAMMER_OBJ, and without them the paths default to this checkout's."""

import gc
import json
import os
import pathlib
import subprocess
import tempfile
import threading
import unittest

import numpy as np

import g2p

ROOT = pathlib.Path(__file__).resolve().parents[2]
HAMMER = os.environ.get("G2P_HAMMER_OBJ", str(ROOT / "examples" / "data" / "hammer.obj"))
SHARED_ASSETS = pathlib.Path(os.environ.get("G2P_SHARED_ASSETS", str(ROOT.parent / "shared" / "assets")))
# The generated set's files come from public repositories and are never
# committed here; the tests that read one skip without it.
SHARED_GENERATED = pathlib.Path(os.environ.get("G2P_SHARED_GENERATED", str(ROOT.parent / "shared" / "generated")))
TRELLIS_CHAIR = SHARED_GENERATED / "trellis_shell_chair.glb"
NO_TRELLIS_CHAIR = f"{TRELLIS_CHAIR} is absent: the generated set is read from ../shared/generated (G2P_SHARED_GENERATED)"

TABLE = g2p.MaterialTable.paper_default()
WOOD, METAL, PLASTIC = TABLE.find("Wood"), TABLE.find("Metal"), TABLE.find("Plastic")


def quick_options(**kwargs):
    """Fewer, smaller views than the paper's 11 at 512 px keep the tests quick."""
    options = g2p.PipelineOptions(**kwargs)
    options.views.num_views = 6
    options.views.width = options.views.height = 160
    return options


class AllPlastic(g2p.Segmenter):
    """Every surface pixel is Plastic; counts its calls on the class (instances are made inline)."""

    calls = 0

    def __init__(self):
        super().__init__()
        self.num_classes = None

    def set_model(self, model, table):
        self.num_classes = len(table)

    def segment(self, view):
        type(self).calls += 1
        assert self.num_classes == len(TABLE)
        face_id = view.face_id
        return np.where(face_id >= 0, PLASTIC, g2p.UNKNOWN_LABEL).astype(np.int64)


class WrongShape(g2p.Segmenter):
    def segment(self, view):
        return np.zeros((3, 4), dtype=np.int32)


class Boom(g2p.Refiner):
    def refine(self, input):
        raise RuntimeError("boom from a Python refiner")


class EverythingMetal(g2p.Refiner):
    def refine(self, input):
        self.saw_faces = input.num_faces
        self.votes_shape = input.votes.shape
        return np.full(input.num_faces, METAL, dtype=np.int32)


class WrappedPartition(g2p.Completer):
    """A Python completer that delegates to the C++ default."""

    def __init__(self):
        super().__init__()
        self.inner = g2p.make_completer("partition")
        self.parts_seen = None

    def complete(self, input):
        self.parts_seen = input.num_parts
        return self.inner.complete(input)


class Water(g2p.PropertyEstimator):
    """Everything weighs 1000 kg/m^3, solid."""

    def estimate(self, input):
        return {"density_kg_m3": 1000.0, "structure": "solid"}


class HammerPipelineTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        progress = []
        cls.result = g2p.Pipeline(quick_options()).run_file(HAMMER, progress=progress.append)
        cls.progress = progress

    def test_two_parts_wood_and_metal(self):
        r = self.result
        self.assertEqual(len(r.parts), 2)
        self.assertEqual(sorted(p["class"] for p in r.parts), ["Metal", "Wood"])
        self.assertEqual(sorted(p["label"] for p in r.parts), sorted([WOOD, METAL]))
        faces = np.concatenate([p["faces"] for p in r.parts])
        self.assertEqual(faces.dtype, np.int32)
        self.assertEqual(sorted(faces.tolist()), list(range(r.model.num_faces)))

    def test_mass_properties(self):
        r = self.result
        # The steel head outweighs the handle: the centre of mass sits high (head at z ~ 0.3 m).
        self.assertGreater(r.center_of_mass[2], 0.25)
        self.assertTrue(0.5 < r.mass_kg < 3.0, r.mass_kg)
        self.assertEqual(r.inertia.shape, (3, 3))
        np.testing.assert_allclose(r.inertia, r.inertia.T, atol=1e-12)
        props = {p["class"]: p for p in r.properties}
        self.assertEqual(set(props), {"Wood", "Metal"})
        self.assertGreater(props["Metal"]["mass_kg"], props["Wood"]["mass_kg"])
        self.assertAlmostEqual(props["Metal"]["density_kg_m3"], TABLE[METAL].density_kg_m3)
        self.assertIn(props["Metal"]["structure"], ("solid", "hollow"))
        self.assertEqual(props["Metal"]["inertia"].shape, (3, 3))
        self.assertAlmostEqual(sum(p["mass_kg"] for p in r.properties), r.mass_kg, places=9)
        for part in r.completion.parts:
            self.assertTrue(part.ok)
            self.assertGreater(part.volume_m3, 0.0)
            self.assertEqual(part.mesh.positions.shape[1], 3)
            self.assertTrue(part.checks.closed)
        self.assertEqual(props["Metal"]["contents_mass_kg"], 0.0)

    def test_a_fill_settles_in_the_bottom_of_a_closed_part(self):
        closed = self.result.completion.parts[0].mesh
        whole = g2p.solid_mass_properties(closed, 1000.0)
        half = g2p.fill_mass_properties(closed, 1000.0, 0.5 * whole.volume_m3)
        self.assertAlmostEqual(half.volume_m3 / whole.volume_m3, 0.5, places=7)
        self.assertAlmostEqual(half.mass_kg / (500.0 * whole.volume_m3), 1.0, places=7)
        self.assertLess(half.center_of_mass[2], whole.center_of_mass[2])
        with self.assertRaises(ValueError):
            g2p.fill_mass_properties(closed, 1000.0, 2.0 * whole.volume_m3)
        p = g2p.PartProperties(contents_fill=0.5, contents_density_kg_m3=790.0)
        self.assertEqual((p.contents_fill, p.contents_density_kg_m3), (0.5, 790.0))

    def test_arrays_have_the_documented_shapes(self):
        r = self.result
        m = r.model.num_faces
        self.assertEqual(m, 104)
        for name in ("face_labels", "projected_labels", "face_part"):
            array = getattr(r, name)
            self.assertEqual((array.shape, array.dtype), ((m,), np.int32), name)
        self.assertEqual(set(r.face_labels.tolist()), {WOOD, METAL})
        self.assertEqual(len(r.views), 6)
        view = r.views[0]
        self.assertEqual((view.rgb.shape, view.rgb.dtype), ((160, 160, 3), np.uint8))
        self.assertEqual((view.face_id.shape, view.face_id.dtype), ((160, 160), np.int32))
        self.assertEqual((view.depth.shape, view.depth.dtype), ((160, 160), np.float32))
        self.assertEqual(view.normal.shape, (160, 160, 3))
        self.assertEqual(view.base_color.shape, (160, 160, 4))
        seen = view.face_id[view.face_id >= 0]
        self.assertGreater(seen.size, 100)
        self.assertLess(seen.max(), m)
        self.assertTrue(np.isinf(view.depth[view.face_id < 0]).all())
        labels = r.label_maps[0].labels
        self.assertEqual((labels.shape, labels.dtype), ((160, 160), np.int32))
        # Background pixels are unknown; surface pixels are Wood or Metal.
        self.assertTrue((labels[view.face_id < 0] == -1).all())
        self.assertTrue(set(np.unique(labels[view.face_id >= 0]).tolist()) <= {WOOD, METAL})
        probabilities = r.label_maps[0].probabilities
        if probabilities is not None:
            self.assertEqual((probabilities.shape, probabilities.dtype), ((160, 160, len(TABLE)), np.float32))

    def test_stage_reports_progress_and_summary(self):
        r = self.result
        self.assertEqual([s["stage"] for s in r.stages],
                         ["load", "render", "identify", "segment", "project", "refine", "complete", "properties",
                          "decompose", "export"])
        for s in r.stages:
            self.assertTrue(s["ok"], s)
            self.assertGreaterEqual(s["seconds"], 0.0)
        self.assertEqual(r.stage(g2p.Stage.SEGMENT)["backend"], "hybrid")  # the default
        self.assertEqual(r.kind, "hammer")  # its file and mesh names
        self.assertEqual(r.identification["source"], "names")
        self.assertEqual(r.summary_json()["identification"]["kind"], "hammer")
        text = r.summary()  # what `g2p run` prints
        self.assertIn("object: hammer (names,", text)
        self.assertEqual(text.count("  part "), 2)
        self.assertIn("  decompose ", text)
        self.assertEqual(r.warnings, [])
        self.assertGreater(r.seconds, 0.0)
        self.assertEqual(self.progress[-1].stage, g2p.Stage.EXPORT)
        self.assertAlmostEqual(self.progress[-1].overall, 1.0)
        overall = [p.overall for p in self.progress]
        self.assertEqual(overall, sorted(overall))
        summary = r.summary_json()
        self.assertEqual(summary["name"], "hammer")
        self.assertEqual(len(summary["parts"]), 2)
        self.assertEqual(r.asset_name, "hammer")

    def test_kind_prior_is_an_option_checked_before_work(self):
        o = quick_options(object="hammer", kind_prior=0.2)
        self.assertAlmostEqual(o.kind_prior, 0.2)
        with self.assertRaisesRegex(g2p.Error, "--kind-prior"):
            g2p.Pipeline(quick_options(kind_prior=0.0)).run_file(HAMMER)

    def test_write_output(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "hammer_out")
            g2p.write_output(out, self.result)
            for name in ("summary.html", "run.json", "hammer.xml", "hammer.urdf", "report.json"):
                self.assertTrue(os.path.isfile(os.path.join(out, name)), name)
            with open(os.path.join(out, "run.json")) as f:
                self.assertEqual(len(json.load(f)["parts"]), 2)
            # An existing folder is only replaced when asked.
            with self.assertRaises(g2p.Error):
                g2p.write_output(out, self.result)
            options = quick_options(formats=["mjcf"])
            g2p.write_output(out, self.result, options, overwrite=True)
            self.assertTrue(os.path.isfile(os.path.join(out, "hammer.xml")))
            self.assertFalse(os.path.exists(os.path.join(out, "hammer.urdf")))

    def test_resume_a_folder_gives_what_the_run_gave(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "hammer_out")
            g2p.write_output(out, self.result)
            # From the folder's labels: complete, properties, decompose and export again.
            resumed = g2p.Pipeline(quick_options()).resume(out, g2p.Stage.COMPLETE, g2p.Stage.EXPORT)
            self.assertEqual([s["stage"] for s in resumed.stages],
                             ["complete", "properties", "decompose", "export"])
            self.assertEqual(resumed.mass_kg, self.result.mass_kg)
            self.assertEqual(resumed.kind, "hammer")
            with self.assertRaisesRegex(g2p.Error, "manifest.json"):
                g2p.Pipeline(quick_options()).resume(tmp, g2p.Stage.COMPLETE)


class ModelSummaryTest(unittest.TestCase):
    def test_the_summary_is_what_g2p_info_prints(self):
        model = g2p.load_model(HAMMER)
        summary = model.summary_json()
        self.assertEqual(summary["faces"], model.num_faces)
        self.assertEqual([m["name"] for m in summary["materials"]], model.material_names)
        self.assertEqual(sum(m["faces"] for m in summary["materials"]), model.num_faces)
        tool = os.environ.get("G2P_TEST_TOOL")
        if not tool:
            self.skipTest("no g2p tool in this build (G2P_TEST_TOOL)")
        info = subprocess.run([tool, "info", str(HAMMER)], capture_output=True, text=True, check=True)
        self.assertEqual(info.stdout, model.summary())


class PythonBackendsTest(unittest.TestCase):
    def test_python_segmenter_runs_inside_the_pipeline(self):
        pipeline = g2p.Pipeline(quick_options())
        AllPlastic.calls = 0
        pipeline.set_segmenter(AllPlastic())  # created inline: the pipeline must keep the Python object alive
        gc.collect()
        r = pipeline.run_file(HAMMER)
        self.assertEqual(AllPlastic.calls, 6)
        self.assertGreaterEqual(len(r.parts), 1)
        self.assertEqual({p["class"] for p in r.parts}, {"Plastic"})
        self.assertEqual({p["class"] for p in r.properties}, {"Plastic"})
        self.assertEqual(r.stage(g2p.Stage.SEGMENT)["backend"], "custom")
        # Back to the named backend.
        pipeline.set_segmenter(None)
        self.assertEqual(sorted(p["class"] for p in pipeline.run_file(HAMMER).parts), ["Metal", "Wood"])

    def test_a_segmenters_warnings_reach_the_result(self):
        class Degraded(AllPlastic):
            def warnings(self):
                return ["fell back to all Plastic (no camera)"]

        pipeline = g2p.Pipeline(quick_options())
        pipeline.set_segmenter(Degraded())
        r = pipeline.run_file(HAMMER)
        self.assertIn("segment: fell back to all Plastic (no camera)", r.warnings)
        # A built-in backend's: hybrid without its network says why, for a
        # model that wants it (a real TRELLIS mesh), not for the named hammer.
        hybrid = g2p.make_segmenter("hybrid", {"model_card": "/nonexistent/g2p-materials.json"})
        if not TRELLIS_CHAIR.is_file():
            self.skipTest(NO_TRELLIS_CHAIR)
        hybrid.set_model(g2p.load_model(str(TRELLIS_CHAIR)))
        self.assertEqual(len(hybrid.warnings()), 1)
        self.assertIn("the network cannot run", hybrid.warnings()[0])
        hybrid.set_model(g2p.load_model(HAMMER))
        self.assertEqual(hybrid.warnings(), [])
        self.assertEqual(g2p.make_segmenter("pbr").warnings(), [])

    def test_the_image_decided_faces_reach_the_refiner(self):
        # hybrid gives a real TRELLIS mesh (one atlas material, no names) to its
        # network, and the named hammer to pbr.
        if not TRELLIS_CHAIR.is_file():
            self.skipTest(NO_TRELLIS_CHAIR)
        hybrid = g2p.make_segmenter("hybrid")
        trellis = g2p.load_model(str(TRELLIS_CHAIR))
        hybrid.set_model(trellis)
        decided = hybrid.image_decided_faces()
        self.assertEqual(decided.dtype, np.uint8)
        self.assertEqual(decided.shape, (trellis.mesh.num_faces,))
        self.assertTrue((decided == 1).all())
        hybrid.set_model(g2p.load_model(HAMMER))
        self.assertTrue((hybrid.image_decided_faces() == 0).all())
        self.assertIsNone(AllPlastic().image_decided_faces(), "a Python segmenter that does not say")

        # A Python segmenter that says the image decided the first half of
        # the faces: a Python refiner sees it.
        class HalfByImage(AllPlastic):
            def image_decided_faces(self):
                return np.array([1] * 52 + [0] * 52, dtype=np.uint8)

        class Looks(g2p.Refiner):
            def refine(self, input):
                self.decided = input.image_decided
                return input.labels

        pipeline = g2p.Pipeline(quick_options())
        looks = Looks()
        pipeline.set_segmenter(HalfByImage())
        pipeline.set_refiner(looks)
        pipeline.run_file(HAMMER)
        np.testing.assert_array_equal(looks.decided, [1] * 52 + [0] * 52)

    def test_segmenter_output_is_checked(self):
        pipeline = g2p.Pipeline(quick_options())
        pipeline.set_segmenter(WrongShape())
        with self.assertRaises(g2p.Error) as caught:
            pipeline.run_file(HAMMER)
        message = str(caught.exception)
        self.assertIn("WrongShape.segment", message)
        self.assertIn("(160, 160)", message)
        self.assertIn("(3, 4)", message)

    def test_failing_python_refiner_degrades_the_run(self):
        pipeline = g2p.Pipeline(quick_options())
        pipeline.set_refiner(Boom())
        r = pipeline.run_file(HAMMER)
        refine = r.stage(g2p.Stage.REFINE)
        self.assertFalse(refine["ok"])
        self.assertIn("boom from a Python refiner", refine["error"])
        self.assertIn("Traceback", refine["error"])
        self.assertEqual(len(r.warnings), 1)
        self.assertIn("refine", r.warnings[0])
        # The projected labels stand and the later stages ran.
        np.testing.assert_array_equal(r.face_labels, r.projected_labels)
        self.assertEqual(sorted(p["class"] for p in r.parts), ["Metal", "Wood"])
        self.assertTrue(r.stage(g2p.Stage.EXPORT)["ok"])

    def test_python_refiner_changes_labels(self):
        pipeline = g2p.Pipeline(quick_options())
        refiner = EverythingMetal()
        pipeline.set_refiner(refiner)
        r = pipeline.run_file(HAMMER)
        self.assertEqual(refiner.saw_faces, 104)
        self.assertEqual(refiner.votes_shape, (104, len(TABLE)))
        self.assertTrue((r.face_labels == METAL).all())
        self.assertIn(WOOD, r.projected_labels.tolist())
        self.assertEqual({p["class"] for p in r.parts}, {"Metal"})  # handle and head are separate pieces
        changed = int((r.projected_labels != METAL).sum())
        self.assertEqual(len(r.refinement.changes), changed)

    def test_python_completer_and_estimator(self):
        # The hammer's head and handle are closed solids, kept as given unless
        # told otherwise; here the Python completer closes them.
        options = quick_options()
        options.keep_closed_parts = False
        pipeline = g2p.Pipeline(options)
        completer, estimator = WrappedPartition(), Water()
        pipeline.set_completer(completer)
        pipeline.set_estimator(estimator)
        r = pipeline.run_file(HAMMER)
        self.assertEqual(completer.parts_seen, 2)
        self.assertEqual(r.stage(g2p.Stage.COMPLETE)["backend"], "custom")
        self.assertEqual(len(r.properties), 2)  # both parts weighed by the Python estimator
        for p in r.properties:
            self.assertEqual(p["density_kg_m3"], 1000.0)
            self.assertEqual(p["sources"]["density"], "user")
            self.assertAlmostEqual(p["mass_kg"], 1000.0 * p["volume_m3"], places=9)
        self.assertAlmostEqual(r.mass_kg, sum(p["mass_kg"] for p in r.properties), places=9)
        self.assertGreater(r.mass_kg, 0.0)
        # Water is lighter than the steel head: the centre of mass drops from
        # the head (z 0.30-0.34 m) towards the middle of the handle.
        self.assertGreater(r.center_of_mass[2], 0.05)
        self.assertLess(r.center_of_mass[2], 0.25)

    def test_python_estimator_errors_fail_the_run_with_the_traceback(self):
        class Broken(g2p.PropertyEstimator):
            def estimate(self, input):
                return {"no_such_field": 1.0}

        pipeline = g2p.Pipeline(quick_options())
        pipeline.set_estimator(Broken())
        with self.assertRaises(g2p.Error) as caught:
            pipeline.run_file(HAMMER)
        self.assertIn("no_such_field", str(caught.exception))


class ErrorsAndCancellationTest(unittest.TestCase):
    def test_unknown_backend_name(self):
        pipeline = g2p.Pipeline(quick_options(segmenter="no-such-segmenter"))
        with self.assertRaises(g2p.NotFoundError) as caught:
            pipeline.run_file(HAMMER)
        self.assertIsInstance(caught.exception, g2p.Error)
        self.assertIsInstance(caught.exception, LookupError)
        self.assertEqual(caught.exception.code, g2p.StatusCode.NOT_FOUND)
        self.assertIn("no-such-segmenter", str(caught.exception))
        self.assertIn("pbr", str(caught.exception))  # the known names are listed
        with self.assertRaises(g2p.NotFoundError):
            g2p.make_refiner("no-such-refiner")

    def test_too_little_memory_is_a_memory_error(self):
        with self.assertRaises(g2p.OutOfMemoryError) as caught:
            g2p.Pipeline(quick_options(memory_limit_bytes=1000)).run_file(HAMMER)
        self.assertIsInstance(caught.exception, MemoryError)
        self.assertIsInstance(caught.exception, g2p.Error)
        self.assertEqual(caught.exception.code, g2p.StatusCode.OUT_OF_MEMORY)
        self.assertIn("--resolution", str(caught.exception))

    def test_a_file_that_crashes_assimp_is_a_parse_error(self):
        # Found by fuzzing: Debian's assimp segfaults on it; it is parsed in a
        # child process, so this interpreter survives and gets the reason.
        crash = ROOT / "fuzz" / "corpus" / "import_glb" / "assimp-crash-f307c5ba.glb"
        self.assertTrue(g2p.ImportOptions().isolate_reader)
        with self.assertRaises(g2p.ParseError) as caught:
            g2p.load_model(str(crash))
        self.assertIn("crashed on this file (segmentation fault in libassimp.so", str(caught.exception))
        self.assertEqual(g2p.load_model(HAMMER, g2p.ImportOptions(isolate_reader=False)).mesh.num_faces, 104)

    def test_bad_setting_is_a_value_error(self):
        with self.assertRaises(ValueError) as caught:
            g2p.make_refiner("smooth", {"no_such_key": "1"})
        self.assertIsInstance(caught.exception, g2p.Error)
        self.assertIn("no_such_key", str(caught.exception))

    def test_missing_file(self):
        with self.assertRaises(g2p.Error) as caught:
            g2p.load_model("/nonexistent/model.glb")
        self.assertIn("/nonexistent/model.glb", str(caught.exception))

    def test_progress_returning_false_cancels(self):
        stages = []

        def progress(p):
            stages.append(p.stage)
            return p.stage != g2p.Stage.SEGMENT

        with self.assertRaises(g2p.Cancelled) as caught:
            g2p.Pipeline(quick_options()).run_file(HAMMER, progress=progress)
        self.assertEqual(caught.exception.code, g2p.StatusCode.CANCELLED)
        self.assertIn("segment", str(caught.exception))
        self.assertNotIn(g2p.Stage.PROJECT, stages)

    def test_progress_exception_cancels_and_is_reraised(self):
        class Stop(Exception):
            pass

        def progress(p):
            if p.stage == g2p.Stage.RENDER and p.stage_fraction > 0.4:
                raise Stop("enough")

        with self.assertRaises(Stop):
            g2p.Pipeline(quick_options()).run_file(HAMMER, progress=progress)

    def test_run_context_cancel_from_another_thread(self):
        started = threading.Event()
        release = threading.Event()

        def progress(p):
            if p.stage == g2p.Stage.RENDER:
                started.set()
                release.wait(10)  # holds the run here until the other thread has cancelled

        context = g2p.RunContext(progress)

        def canceller():
            started.wait(10)
            context.cancel()
            release.set()

        thread = threading.Thread(target=canceller)
        thread.start()
        with self.assertRaises(g2p.Cancelled):
            g2p.Pipeline(quick_options()).run_file(HAMMER, context=context)
        thread.join()
        self.assertTrue(context.cancelled)


class ModelsAndStagesTest(unittest.TestCase):
    def test_load_hammer(self):
        model = g2p.load_model(HAMMER)
        mesh = model.mesh
        self.assertEqual((mesh.positions.shape[1], mesh.positions.dtype), (3, np.float64))
        self.assertEqual((mesh.triangles.shape, mesh.triangles.dtype), ((104, 3), np.int32))
        self.assertEqual(model.num_faces, 104)
        self.assertLess(mesh.triangles.max(), mesh.num_vertices)
        self.assertEqual(sorted(model.material_names), ["oak_handle", "steel_head"])
        self.assertEqual(mesh.face_source.shape, (104, 3))
        lo, hi = mesh.bounds()
        self.assertGreater(hi[2] - lo[2], 0.25)  # a hammer about 0.3 m tall, +Z up

    def test_import_options_as_keywords(self):
        model = g2p.load_model(HAMMER, unit_scale=0.5)
        full = g2p.load_model(HAMMER)
        np.testing.assert_allclose(model.mesh.positions, full.mesh.positions * 0.5, rtol=1e-6, atol=1e-7)
        with self.assertRaises(TypeError):
            g2p.load_model(HAMMER, no_such_option=1)

    def test_shared_asset_with_textures(self):
        path = SHARED_ASSETS / "WaterBottle" / "WaterBottle.glb"
        model = g2p.load_model(str(path))
        self.assertGreater(model.num_faces, 0)
        self.assertEqual(model.mesh.triangles.shape, (model.num_faces, 3))
        textures = [m.base_color_texture.image for m in model.materials if not m.base_color_texture.empty]
        self.assertGreater(len(textures), 0)
        self.assertEqual(textures[0].ndim, 3)
        self.assertEqual((textures[0].shape[2], textures[0].dtype), (4, np.uint8))
        self.assertEqual(model.mesh.uvs.shape, (model.num_vertices, 2))

    def test_model_from_arrays_runs_the_pipeline(self):
        # A 10 cm cube of "steel": about 7.8 kg with the default table.
        corners = np.array([[x, y, z] for z in (0, 0.1) for y in (0, 0.1) for x in (0, 0.1)], dtype=np.float64)
        quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
        triangles = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))], dtype=np.int32)
        model = g2p.Model.from_arrays(corners, triangles, material_names=["steel"], name="cube")
        self.assertEqual(model.num_faces, 12)
        self.assertAlmostEqual(model.mesh.surface_area(), 0.06, places=6)  # float32 positions
        r = g2p.Pipeline(quick_options()).run(model)
        self.assertEqual([p["class"] for p in r.parts], ["Metal"])
        self.assertEqual(r.asset_name, "cube")
        # Steel with the table's rule: a solid block (rho V) or a sheet-metal box (rho A t).
        (steel,) = r.properties
        rho = TABLE[METAL].density_kg_m3
        expected = rho * 0.001 if steel["structure"] == "solid" else rho * 0.06 * steel["wall_thickness_m"]
        self.assertLess(abs(r.mass_kg - expected) / expected, 0.15, (r.mass_kg, steel["structure"]))
        # Filled with water instead (solid by request): about 1 kg.
        pipeline = g2p.Pipeline(quick_options())
        pipeline.set_estimator(Water())
        self.assertLess(abs(pipeline.run(model).mass_kg - 1.0), 0.15)
        np.testing.assert_allclose(r.center_of_mass, [0.05, 0.05, 0.05], atol=0.01)
        # The caller's model is unchanged (the run took a copy).
        self.assertEqual(model.num_faces, 12)

    def test_from_arrays_rejects_bad_indices(self):
        with self.assertRaises(g2p.InvalidArgumentError) as caught:
            g2p.Model.from_arrays(np.zeros((3, 3)), np.array([[0, 1, 7]]))
        self.assertIn("7", str(caught.exception))
        with self.assertRaises(ValueError):
            g2p.Model.from_arrays(np.zeros((3, 2)), np.array([[0, 1, 2]]))

    def test_render_lights(self):
        model = g2p.load_model(HAMMER)
        cameras = g2p.make_views(model.mesh, g2p.ViewOptions(num_views=1, width=64, height=64))
        renderer = g2p.make_renderer("embree")
        studio = g2p.studio_lights()
        self.assertEqual(len(studio), 3)
        self.assertAlmostEqual(studio[0].irradiance, 2.4, places=5)
        default = g2p.render_views(renderer, model, cameras)[0].rgb
        explicit = g2p.render_views(renderer, model, cameras, g2p.RenderOptions(lights=studio))[0].rgb
        np.testing.assert_array_equal(default, explicit)
        dim = g2p.RenderOptions(lights=[g2p.CameraLight(direction=np.array([0.0, 0.0, -1.0]), irradiance=0.2)])
        darker = g2p.render_views(renderer, model, cameras, dim)[0]
        hit = darker.face_id >= 0
        self.assertLess(darker.rgb[hit].mean(), default[hit].mean() - 10)
        bad = g2p.RenderOptions(lights=[g2p.CameraLight(irradiance=-1.0)])
        with self.assertRaises(ValueError) as caught:
            g2p.render_views(renderer, model, cameras, bad)
        self.assertIn("lights[0]", str(caught.exception))

    def test_stages_one_by_one(self):
        model = g2p.load_model(HAMMER)
        cameras = g2p.make_views(model.mesh, g2p.ViewOptions(num_views=4, width=96, height=96))
        self.assertEqual(len(cameras), 4)
        renderer = g2p.make_renderer("embree")
        views = g2p.render_views(renderer, model, cameras)
        self.assertEqual(views[0].rgb.shape, (96, 96, 3))
        segmenter = g2p.make_segmenter("pbr")
        segmenter.set_model(model)
        maps = [segmenter.segment(v) for v in views]
        self.assertEqual(maps[0].labels.shape, (96, 96))
        projection = g2p.project(model.mesh, views, maps)
        self.assertEqual(sorted(p.label for p in projection.parts), sorted([WOOD, METAL]))
        refined = g2p.refine(g2p.make_refiner("smooth"), model.mesh, projection, views)
        self.assertEqual(refined.labels.shape, (104,))
        completion = g2p.complete(g2p.make_completer(), model.mesh, projection.parts)
        self.assertEqual(len(completion.parts), 2)
        report = g2p.estimate_properties(model.mesh, projection.parts, completion, g2p.make_estimator())
        self.assertGreater(report.object.center_of_mass[2], 0.25)
        self.assertEqual(len(report.to_json()["parts"]), 2)

    def test_python_renderer_wrapping_embree(self):
        class Wrapped(g2p.Renderer):
            def __init__(self):
                super().__init__()
                self.inner = g2p.make_renderer()
                self.rendered = 0

            def set_model(self, model):
                self.model = model
                self.inner.set_model(model)

            def render(self, camera, options):
                self.rendered += 1
                return self.inner.render(camera, options)

        pipeline = g2p.Pipeline(quick_options())
        renderer = Wrapped()
        pipeline.set_renderer(renderer)
        r = pipeline.run_file(HAMMER)
        # The 6 views, then the detector's 8 eye-level views of its own and the kind classifier's 8 (identify),
        # through the same renderer.
        self.assertEqual(renderer.rendered, 6 + 8 + 8)
        self.assertEqual(sorted(p["class"] for p in r.parts), ["Metal", "Wood"])

    def test_options(self):
        options = g2p.PipelineOptions(refiner="none", name="thing")
        self.assertEqual(options.refiner.name, "none")
        self.assertEqual(options.name, "thing")
        options.segmenter.settings["model"] = "m.onnx"  # edited in place
        self.assertEqual(dict(options.segmenter.settings), {"model": "m.onnx"})
        options.completer = g2p.BackendChoice("external", {"command": "true"})
        self.assertEqual(options.completer.settings["command"], "true")
        options.views.num_views = 3
        self.assertEqual(options.views.num_views, 3)
        self.assertEqual(g2p.ViewOptions(width=64).width, 64)
        with self.assertRaises(TypeError):
            g2p.ViewOptions(no_such_field=1)
        pipeline = g2p.Pipeline(options)
        pipeline.options.views.width = 100
        self.assertEqual(pipeline.options.views.width, 100)
        self.assertEqual(pipeline.options.refiner.name, "none")


class OneHullPerPart(g2p.Decomposer):
    """A Python decomposer: the convex hull of the part's vertices, as points."""

    def __init__(self):
        super().__init__()
        self.calls = 0

    def decompose(self, closed, options):
        self.calls += 1
        return [closed.positions]


class Raises(g2p.Decomposer):
    def decompose(self, closed, options):
        raise RuntimeError("no hulls today")


class DecomposeTest(unittest.TestCase):
    def test_convex_hull_of_a_cube(self):
        corners = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
        inside = np.random.default_rng(3).uniform(0.1, 0.9, size=(50, 3))
        hull = g2p.convex_hull(np.vstack([corners, inside]))
        self.assertEqual(hull.num_vertices, 8)
        self.assertAlmostEqual(g2p.enclosed_volume(hull), 1.0, places=5)
        with self.assertRaises(ValueError):
            g2p.convex_hull(np.zeros((5, 3)))

    def test_pipeline_decomposes_every_part(self):
        r = g2p.Pipeline(quick_options()).run_file(HAMMER)
        self.assertIn("decompose", [s["stage"] for s in r.stages])
        self.assertEqual(len(r.collision), len(r.parts))
        for d in r.collision:
            self.assertEqual(d.backend, "voxel-cut")
            self.assertGreaterEqual(len(d.hulls), 1)
            for h in d.hulls:
                self.assertLessEqual(h.num_vertices, 64)
            self.assertGreaterEqual(d.hull_budget, 16)
            self.assertGreater(d.coverage_tolerance_m, 0)
            self.assertGreaterEqual(d.uncovered_max_m, d.uncovered_mean_m)
            self.assertGreaterEqual(d.uncovered_mean_m, 0)
        one = quick_options()
        one.decompose.max_hulls = 1
        one.decompose.max_hulls_per_object = 0  # no budget raised for --coverage-tolerance
        self.assertAlmostEqual(one.decompose.coverage_tolerance, 0.03)
        for d in g2p.Pipeline(one).run_file(HAMMER).collision:
            self.assertEqual(len(d.hulls), 1)

    def test_python_decomposer(self):
        decomposer = OneHullPerPart()
        pipeline = g2p.Pipeline(quick_options())
        pipeline.set_decomposer(decomposer)
        r = pipeline.run_file(HAMMER)
        self.assertEqual(decomposer.calls, len(r.parts))
        for d in r.collision:
            self.assertEqual(d.backend, "custom")
            self.assertFalse(d.fell_back)
            self.assertEqual(len(d.hulls), 1)

    def test_failing_python_decomposer_falls_back_to_the_single_hull(self):
        pipeline = g2p.Pipeline(quick_options())
        pipeline.set_decomposer(Raises())
        r = pipeline.run_file(HAMMER)
        for d in r.collision:
            self.assertTrue(d.fell_back)
            self.assertEqual(d.backend, "hull")
            self.assertEqual(len(d.hulls), 1)
            self.assertIn("no hulls today", d.notes[-1])

    def test_names_and_bad_input(self):
        self.assertIn("voxel-cut", g2p.decomposer_names())
        self.assertIn("hull", g2p.decomposer_names())
        with self.assertRaises(g2p.NotFoundError):
            g2p.make_decomposer("no-such-decomposer")
        with self.assertRaises(ValueError):
            g2p.make_decomposer("voxel-cut", {"resolution": "2"})
        with self.assertRaises(g2p.NotFoundError):
            g2p.Pipeline(quick_options(decomposer=g2p.BackendChoice("no-such-decomposer"))).run_file(HAMMER)


class BackendSettingsTest(unittest.TestCase):
    """Settings as the backends describe them (docs/settings.md)."""

    def test_listed_with_types_ranges_and_defaults(self):
        hybrid = g2p.backend_settings("hybrid")
        self.assertEqual([(b["stage"], b["backend"]) for b in hybrid], [("segment", "hybrid")])
        share = next(s for s in hybrid[0]["settings"] if s["key"] == "share")
        self.assertEqual((share["type"], share["range"], share["value"]), ("number", "(0, 1]", "0.99"))
        self.assertTrue(share["help"])
        stages = {b["stage"] for b in g2p.backend_settings("vlm")}
        self.assertEqual(stages, {"identify", "refine", "properties"})
        with self.assertRaises(g2p.NotFoundError):
            g2p.backend_settings("no-such-backend")

    def test_keywords_as_the_command_line_writes_them(self):
        d = g2p.make_decomposer("voxel-cut", resolution=96, error=0.05)
        values = {s["key"]: s["value"] for s in d.settings()}
        self.assertEqual((values["resolution"], values["error"]), ("96", "0.05"))
        s = g2p.make_segmenter("pbr", names=False)
        self.assertEqual({x["key"]: x["value"] for x in s.settings()}["names"], "off")
        choice = g2p.BackendChoice("hybrid", colour=False, share=0.5)
        self.assertEqual(dict(choice.settings), {"colour": "off", "share": "0.5"})
        # A bad keyword fails before any work and names what the setting takes.
        with self.assertRaises(ValueError) as bad:
            g2p.Pipeline(quick_options(segmenter=g2p.BackendChoice("hybrid", share=2))).prepare()
        self.assertIn("share takes a number in (0, 1]", str(bad.exception))

    def test_a_refused_setting_changes_nothing(self):
        r = g2p.make_refiner("smooth")
        before = r.settings()
        with self.assertRaises(ValueError):
            r.configure({"lambda": "3", "sweeps": "-1"})
        self.assertEqual(r.settings(), before)


class OverridesTest(unittest.TestCase):
    """Corrections from a file (docs/pipeline.md#overrides) on a run."""

    FIX = {
        "format": "g2p-overrides",
        "version": 1,
        "overrides": [
            {"part": 0, "was": {"class": "Wood"}, "class": "Plastic"},
            {"part": 1, "structure": "hollow", "wall_thickness_m": 0.004, "density_kg_m3": 7000},
        ],
    }

    def test_a_run_applies_them(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "fix.json")
            with open(path, "w") as f:
                json.dump(self.FIX, f)
            overrides = g2p.read_overrides(path)
        self.assertEqual(len(overrides), 2)
        self.assertTrue(overrides.changes_classes and overrides.changes_properties)
        plain = g2p.Pipeline(quick_options()).run_file(HAMMER)
        fixed = g2p.Pipeline(quick_options(overrides=overrides)).run_file(HAMMER)
        self.assertEqual([p["class"] for p in fixed.parts], ["Plastic", "Metal"])
        head = fixed.properties[1]
        self.assertEqual(head["structure"], "hollow")
        self.assertAlmostEqual(head["wall_thickness_m"], 0.004)
        self.assertAlmostEqual(head["density_kg_m3"], 7000.0)
        self.assertEqual(len(fixed.overrides_applied), 2)
        self.assertLess(fixed.mass_kg, 0.8 * plain.mass_kg)
        # The text round-trips.
        again = g2p.parse_overrides(overrides.to_json())
        self.assertEqual(again.to_json(), overrides.to_json())

    def test_a_result_resumes_with_them_in_memory(self):
        plain = g2p.Pipeline(quick_options()).run_file(HAMMER)
        density = g2p.parse_overrides(json.dumps(dict(self.FIX, overrides=[{"part": 1, "density_kg_m3": 7000}])))
        self.assertFalse(density.changes_classes)
        # A property correction goes back to properties, not to the views.
        resumed = g2p.Pipeline(quick_options(overrides=density)).resume(plain, g2p.Stage.EXPORT)
        self.assertEqual([s["stage"] for s in resumed.stages], ["properties", "decompose", "export"])
        self.assertAlmostEqual(resumed.properties[1]["density_kg_m3"], 7000.0)
        head = plain.properties[1]
        self.assertAlmostEqual(resumed.properties[1]["mass_kg"], head["mass_kg"] * 7000.0 / head["density_kg_m3"],
                               delta=1e-9 + 1e-6 * head["mass_kg"])
        self.assertEqual(resumed.properties[0]["mass_kg"], plain.properties[0]["mass_kg"])
        # The earlier result is unchanged; the resumed one is the file-based run's.
        self.assertNotAlmostEqual(plain.properties[1]["density_kg_m3"], 7000.0)
        fixed = g2p.Pipeline(quick_options(overrides=density)).run_file(HAMMER)
        self.assertAlmostEqual(resumed.mass_kg, fixed.mass_kg, delta=1e-9)
        # A class correction goes back to complete.
        plastic = g2p.parse_overrides(json.dumps(dict(self.FIX, overrides=self.FIX["overrides"][:1])))
        relabelled = g2p.Pipeline(quick_options(overrides=plastic)).resume(plain, g2p.Stage.EXPORT)
        self.assertEqual([s["stage"] for s in relabelled.stages][0], "complete")
        self.assertEqual([p["class"] for p in relabelled.parts], ["Plastic", "Metal"])

    def test_a_bad_entry_is_named(self):
        bad = dict(self.FIX, overrides=[{"part": 0, "density_kg_m3": -1}])
        with self.assertRaises(g2p.InvalidArgumentError) as caught:
            g2p.parse_overrides(json.dumps(bad), origin="fix.json")
        self.assertIn("fix.json: overrides entry 1: 'density_kg_m3'", str(caught.exception))
        wrong_run = dict(self.FIX, overrides=[{"part": 0, "was": {"class": "Glass"}, "class": "Metal"}])
        with self.assertRaises(g2p.InvalidArgumentError) as caught:
            g2p.Pipeline(quick_options(overrides=g2p.parse_overrides(json.dumps(wrong_run)))).run_file(HAMMER)
        self.assertIn("another model or run", str(caught.exception))


if __name__ == "__main__":
    unittest.main()
