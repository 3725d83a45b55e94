"""The Blender add-on's plain module (blender/g2p_blender/core.py), without Blender:
the in-memory GLB reaches g2p in the add-on's frame with its materials, options
set only what is given, corrections become overrides."""

import os
import sys
import unittest

import numpy as np

import g2p

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "blender", "g2p_blender"))
import core  # noqa: E402  (the add-on's package imports bpy; core does not)

HAMMER = os.environ.get("G2P_HAMMER_OBJ",
                        os.path.join(os.path.dirname(__file__), "..", "..", "examples", "data", "hammer.obj"))


def two_boxes():
    """Two unit cubes side by side (2 x 1 x 1 m), one material each."""
    corners = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=np.float64)
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    triangles = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))])
    data = core.MeshInput("boxes")
    steel = {"name": "steel", "base_color": (0.5, 0.5, 0.5, 1.0), "metallic": 1.0, "roughness": 0.3}
    oak = {"name": "oak", "base_color": (0.4, 0.2, 0.1, 1.0)}
    data.add(corners, triangles, [("steel", steel)], np.zeros(12))
    data.add(corners + [1, 0, 0], triangles, [("oak", oak), ("steel", steel)], np.zeros(12))
    return data


class CoreTest(unittest.TestCase):
    def test_glb_keeps_frame_and_materials(self):
        model = two_boxes().model(g2p)
        self.assertEqual(model.num_faces, 24)
        low, high = model.mesh.bounds()
        np.testing.assert_allclose(low, [0, 0, 0], atol=1e-6)
        np.testing.assert_allclose(high, [2, 1, 1], atol=1e-6)  # +Z up as in Blender, metres
        self.assertEqual(model.material_names, ["steel", "oak"])
        self.assertAlmostEqual(model.materials[0].metallic, 1.0)
        np.testing.assert_allclose(model.materials[1].base_color[:3], [0.4, 0.2, 0.1], atol=1e-6)

    def test_texture_and_uv_seams(self):
        # A 1x1 PNG (red) on a square whose two triangles meet at a UV seam.
        png = bytes.fromhex("89504e470d0a1a0a0000000d4948445200000001000000010802000000907753de"
                            "0000000c4944415408d763f8cfc000000301010018dd8db00000000049454e44ae426082")
        positions = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=np.float64)
        triangles = np.array([[0, 1, 2], [0, 2, 3]])
        corner_uvs = np.array([[0, 0], [1, 0], [1, 1], [0.5, 0], [1, 1], [0, 1]], dtype=np.float64)
        source, split, uvs = core.split_by_uv(triangles, corner_uvs)
        self.assertEqual(len(source), 5)  # vertex 0 has two UVs
        np.testing.assert_allclose(uvs[split.reshape(-1)], corner_uvs)
        np.testing.assert_array_equal(source[split], triangles)
        data = core.MeshInput("square")
        data.add(positions[source], split, [("red", {"name": "red", "base_color_image": (png, "image/png")})],
                 np.zeros(2), uvs)
        model = data.model(g2p)
        texture = model.materials[0].base_color_texture
        self.assertFalse(texture.empty)
        self.assertEqual(texture.image.shape, (1, 1, 4))
        np.testing.assert_allclose(model.mesh.uvs.min(axis=0), [0, 0], atol=1e-6)

    def test_real_size(self):
        model = two_boxes().model(g2p, longest_side_m=0.5)
        np.testing.assert_allclose(model.mesh.bounds()[1], [0.5, 0.25, 0.25], atol=1e-6)

    def test_no_triangles(self):
        with self.assertRaises(ValueError):
            core.MeshInput().glb()

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
