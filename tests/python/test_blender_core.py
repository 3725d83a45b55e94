"""The Blender add-on's plain module (blender/g2p_blender/core.py), without Blender:
options set only what is given, corrections become overrides, runs on a worker
thread (cancelled, or resumed with a correction), the results kept for
corrections. The selection's GLB is Blender's exporter's (tests/blender)."""

import os
import sys
import unittest

import numpy as np

import g2p

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "blender", "g2p_blender"))
import core  # noqa: E402  (the add-on's package imports bpy; core does not)

HAMMER = os.environ.get("G2P_HAMMER_OBJ",
                        os.path.join(os.path.dirname(__file__), "..", "..", "examples", "data", "hammer.obj"))


class CoreTest(unittest.TestCase):
    def test_options_set_only_what_is_given(self):
        defaults = g2p.PipelineOptions()
        options = core.pipeline_options(g2p)
        self.assertEqual(options.segmenter.name, defaults.segmenter.name)
        self.assertEqual(options.decompose.max_hulls, defaults.decompose.max_hulls)
        self.assertEqual(options.formats, [])
        options = core.pipeline_options(g2p, "pbr", "hammer", 3)
        self.assertEqual((options.segmenter.name, options.object, options.decompose.max_hulls), ("pbr", "hammer", 3))
        self.assertEqual(core.library_defaults(g2p)["max_hulls"], defaults.decompose.max_hulls)

    def test_corrections_become_overrides(self):
        overrides = core.correction_overrides(g2p, [{"faces": [0, 1], "class": "Wood", "density_kg_m3": 650}],
                                              g2p.MaterialTable(), 24)
        self.assertEqual(len(overrides), 1)
        self.assertTrue(overrides.changes_classes)
        with self.assertRaises(g2p.Error):
            core.correction_overrides(g2p, [{"faces": [0], "class": "Nothing"}], g2p.MaterialTable(), 24)

    def test_run_on_a_thread_and_its_records(self):
        run = core.Run(g2p, g2p.load_model(HAMMER), core.pipeline_options(g2p))
        run.start()
        run._thread.join(120)
        self.assertIsNone(run.error)
        self.assertEqual(run.progress, 1.0)
        records = core.part_records(run.result)
        self.assertEqual([r["class"] for r in records], [p["class"] for p in run.result.properties])
        self.assertAlmostEqual(sum(r["mass_kg"] for r in records), run.result.mass_kg)
        for r in records:
            self.assertGreater(len(r["triangles"]), 0)
            self.assertGreater(len(r["hulls"]), 0)
        friction, restitution = core.contact_settings(records)
        self.assertTrue(0 < friction < 2 and 0 <= restitution <= 1)

    def test_a_correction_resumes_the_run(self):
        first = core.Run(g2p, g2p.load_model(HAMMER), core.pipeline_options(g2p))
        first.run()
        self.assertIsNone(first.error)
        handle = next(p for p in first.result.properties if p["class"] == "Wood")
        faces = next(p["faces"] for p in first.result.parts if p["index"] == handle["part"])
        overrides = core.correction_overrides(g2p, [{"faces": faces.tolist(), "density_kg_m3": 1000}],
                                              g2p.MaterialTable(), len(first.result.face_labels))
        again = core.Run(g2p, None, core.pipeline_options(g2p, overrides=overrides), previous=first.result)
        again.run()
        self.assertIsNone(again.error)
        self.assertEqual(again.result.stages[0]["stage"], "properties")  # the views and labels are reused
        fixed = next(p for p in again.result.properties if p["part"] == handle["part"])
        self.assertAlmostEqual(fixed["mass_kg"], handle["mass_kg"] * 1000 / handle["density_kg_m3"], places=9)
        self.assertAlmostEqual(handle["density_kg_m3"],
                               next(p for p in first.result.properties if p["class"] == "Wood")["density_kg_m3"])

    def test_the_cache_keeps_the_last_results(self):
        cache = core.ResultCache(size=2)
        keys = [cache.put(n) for n in range(3)]
        self.assertEqual(len(set(keys)), 3)
        self.assertIsNone(cache.get(keys[0]))
        self.assertEqual([cache.get(k) for k in keys[1:]], [1, 2])
        self.assertIsNone(cache.get("no such key"))

    def test_run_on_a_thread_and_cancel(self):
        model = g2p.load_model(HAMMER)
        run = core.Run(g2p, model, core.pipeline_options(g2p))
        run.cancel()  # before it starts: it stops at its first check
        run.start()
        run._thread.join(60)
        self.assertTrue(run.done)
        self.assertTrue(run.cancelled, run.error)
        self.assertIsNone(run.result)

    def test_missing_module_says_where(self):
        saved = sys.modules.pop("g2p")
        sys.modules["g2p"] = None  # an import of it fails
        try:
            with self.assertRaisesRegex(core.ModuleMissing, "module folder"):
                core.import_g2p("/nonexistent")
        finally:
            sys.modules["g2p"] = saved
            sys.path.remove("/nonexistent")


if __name__ == "__main__":
    unittest.main()
