"""g2p.evaluate_segmentation (what `g2p eval seg` runs) on two of the shared
assets, g2p.compare_segmentation_files (`g2p eval compare`) and the mass errors
of `g2p eval mass`. Runs under unittest and
pytest; ctest sets PYTHONPATH to the built module and G2P_SHARED_ASSETS."""

import json
import os
import pathlib
import tempfile
import unittest

import numpy as np

import g2p

ROOT = pathlib.Path(__file__).resolve().parents[2]
SHARED_ASSETS = pathlib.Path(os.environ.get("G2P_SHARED_ASSETS", str(ROOT.parent / "shared" / "assets")))
LABELS = str(SHARED_ASSETS / "labels.json")
MODELS = ["WaterBottle", "SheenChair"]


def quick(**kwargs):
    """Two models, 2 views at 128 px: seconds, not minutes."""
    options = dict(assets=str(SHARED_ASSETS), models=MODELS, views=g2p.ViewOptions(num_views=2, width=128, height=128))
    options.update(kwargs)
    return options


def oracle():
    choice = g2p.BackendChoice("oracle")
    choice.settings["labels"] = LABELS
    return choice


class EvaluateSegmentation(unittest.TestCase):
    def test_the_oracle_scores_perfectly(self):
        seen = []
        result = g2p.evaluate_segmentation(**quick(segmenter=oracle()), on_model=lambda m: seen.append(m["key"]))
        self.assertEqual(seen, MODELS)
        self.assertEqual(result.keys, MODELS)
        self.assertAlmostEqual(result.total.miou, 1.0)
        self.assertAlmostEqual(result.total.accuracy, 1.0)
        self.assertGreater(result.miou, 0.9)  # per face, every model weighing the same
        self.assertAlmostEqual(result.total_3d_per_model.total, 2.0)
        interval = result.interval
        self.assertLessEqual(interval["low"], interval["high"])
        models = result.models
        self.assertEqual([m["key"] for m in models], MODELS)
        self.assertAlmostEqual(models[1]["2d"]["miou"], 1.0)
        self.assertEqual(models[1]["kind"], "unknown")
        self.assertNotIn("refine", models[1])
        # The matrices themselves: rows the truth, columns the prediction then unknown.
        faces = result.matrices()
        self.assertEqual(len(faces), 2)
        counts = result.total.counts
        self.assertEqual(counts.shape, (len(g2p.MaterialTable()), len(g2p.MaterialTable()) + 1))
        self.assertAlmostEqual(float(np.trace(counts[:, :-1])), result.total.total)

        # The text `g2p eval seg` prints, and the document its --json writes, schema and all.
        self.assertIn("All 2 models, one confusion matrix", str(result))
        self.assertIn("mIoU", result.to_text())
        doc = json.loads(result.to_json())
        self.assertEqual(doc, result.json())
        self.assertEqual(doc["segmenter"], "oracle")
        self.assertEqual(doc["vote"], "hard")
        self.assertEqual(doc["views"], 2)
        self.assertEqual(doc["resolution"], 128)
        for key in ("total", "total_3d", "total_3d_per_model", "total_3d_per_model_interval", "calibration"):
            self.assertIn(key, doc)
        self.assertEqual(sorted(doc["models"]), sorted(MODELS))
        self.assertAlmostEqual(doc["models"]["SheenChair"]["2d"]["miou"], 1.0)

        # `g2p eval compare` on that file against itself: the same models, no difference.
        with tempfile.TemporaryDirectory() as tmp:
            path = str(pathlib.Path(tmp) / "eval.json")
            pathlib.Path(path).write_text(result.to_json() + "\n")
            compared = g2p.compare_segmentation_files(path, path, resamples=100)
            self.assertEqual((compared["models"], compared["difference"], compared["resamples"]), (2, 0.0, 100))
            self.assertIn("not resolved: the interval includes zero", compared["text"])

    def test_options_object_soft_votes_and_a_refiner(self):
        options = g2p.SegmentationEvalOptions(**quick(segmenter="pbr", refiner="smooth"))
        options.project.vote.mode = g2p.VoteMode.SOFT
        options.models = ["SheenChair"]
        result = g2p.evaluate_segmentation(options)
        doc = result.json()
        self.assertEqual(doc["vote"], "soft")
        self.assertEqual(doc["refiner"], "smooth")
        refine = result.models[0]["refine"]
        self.assertEqual(refine["refiner"], "smooth")
        self.assertIn("changed_faces", refine)
        self.assertEqual(result.options.segmenter.name, "pbr")
        with self.assertRaises(TypeError):
            g2p.evaluate_segmentation(options, assets="elsewhere")

    def test_a_bad_key_names_it(self):
        with self.assertRaises(g2p.NotFoundError) as caught:
            g2p.evaluate_segmentation(**quick(models=["WaterBottle", "NoSuchModel"]))
        self.assertIn("'NoSuchModel'", str(caught.exception))
        self.assertIn("--models", str(caught.exception))
        with self.assertRaises(g2p.InvalidArgumentError) as caught:
            g2p.evaluate_segmentation(**quick(object_from_names=True))
        self.assertIn("--object-from-names", str(caught.exception))
        with self.assertRaises(TypeError):
            g2p.evaluate_segmentation(asset="typo")

    def test_on_model_returning_false_cancels(self):
        seen = []

        def stop(model):
            seen.append(model["key"])
            return False

        with self.assertRaises(g2p.Cancelled):
            g2p.evaluate_segmentation(**quick(segmenter=oracle()), on_model=stop)
        self.assertEqual(seen, MODELS[:1])


class Mass(unittest.TestCase):
    def test_the_four_metrics(self):
        e = g2p.mass_errors([2.0, 1.0], [1.0, 2.0])
        self.assertEqual(e["objects"], 2)
        self.assertAlmostEqual(e["ade_kg"], 1.0)
        self.assertAlmostEqual(e["alde"], np.log(2.0))
        self.assertAlmostEqual(e["ape"], 0.75)
        self.assertAlmostEqual(e["mnre"], 0.5)
        with self.assertRaises(g2p.InvalidArgumentError):
            g2p.mass_errors([1.0], [0.0])

    def test_a_csv(self):
        with tempfile.TemporaryDirectory() as tmp:
            good = pathlib.Path(tmp) / "masses.csv"
            good.write_text("object,predicted_kg,true_kg\nchair,2,1\nbottle,1,2\n")
            self.assertAlmostEqual(g2p.mass_errors_from_csv(str(good))["mnre"], 0.5)
            bad = pathlib.Path(tmp) / "bad.csv"
            bad.write_text("object,predicted_kg,true_kg\nchair,two,1\n")
            with self.assertRaises(g2p.ParseError) as caught:
                g2p.mass_errors_from_csv(str(bad))
            self.assertIn("bad.csv:2", str(caught.exception))


if __name__ == "__main__":
    unittest.main()
