#!/usr/bin/python3
"""tools/training/ensemble.py: the ensemble outputs logits whose softmax is the normalised geometric mean of its
members' probabilities, each member is
rebuilt as train.py exported it (logit adjustment folded in), members validated on other models are refused,
and the exported ONNX model, its weights in int8, is one the `onnx` backend (OpenCV 4.6) loads and runs.

    ensemble_test.py [G2P_CLI SHARED_ASSETS]   (ctest passes both; without them the OpenCV check is skipped)"""
import json
import os
import subprocess
import sys
import tempfile
import unittest

import torch
import torch.nn.functional as F

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", ".."))  # the repository root: tools.training is a package
sys.path.insert(0, HERE)
from tools.training import ensemble, onnx_weights  # noqa: E402
from tools.training.model import COMBINES, Ensemble, UNet  # noqa: E402
from tools.training.runs import build_member, read_runs  # noqa: E402
from train_test import DatasetCase, seeded, snapshot, write_run  # noqa: E402

ENSEMBLE = os.path.join(HERE, "..", "..", "tools", "training", "ensemble.py")
CLI, ASSETS = (sys.argv[1:3] + [None, None])[:2]


class EnsembleTest(unittest.TestCase):
    def test_the_output_is_the_mean_of_the_members_log_probabilities(self):
        a, b = (seeded(UNet(inputs=3), s).eval() for s in (1, 2))
        x = torch.randn(2, 3, 32, 32)
        pa, pb = F.softmax(a(x), 1), F.softmax(b(x), 1)
        self.assertFalse(torch.allclose(pa, pb, atol=1e-3))  # the members disagree: the checks below can fail
        geometric = (pa * pb).sqrt()
        for combine in COMBINES:
            out = Ensemble([a, b], combine).eval()(x)
            torch.testing.assert_close(F.softmax(out, 1), geometric / geometric.sum(1, keepdim=True), rtol=1e-4,
                                       atol=1e-6)
        torch.testing.assert_close(Ensemble([a, b]).eval()(x), (a(x) + b(x)) / 2)  # "logits" by default
        with self.assertRaisesRegex(ValueError, "combine must be one of logits, log_softmax, not 'max'"):
            Ensemble([a, b], "max")

    def test_the_mean_of_logits_exports_without_log_softmax(self):
        import onnx  # python3-onnx
        members = [seeded(UNet(inputs=3), s).eval() for s in (1, 2)]
        with tempfile.TemporaryDirectory() as tmp:
            ops = {}
            for combine in COMBINES:
                path = os.path.join(tmp, combine + ".onnx")
                ensemble.export_ensemble(Ensemble(members, combine).eval(), 3, 32, path)
                ops[combine] = [n.op_type for n in onnx.load(path).graph.node]
        # OpenCV spends 14 % of a two-member ensemble's time in these (docs/performance.md).
        for op in ("LogSoftmax", "ReduceMean", "Transpose"):
            self.assertEqual(ops["logits"].count(op), 0, op)
            self.assertGreater(ops["log_softmax"].count(op), 0, op)
        self.assertEqual(ops["logits"].count("Conv"), ops["log_softmax"].count("Conv"))

    def test_members_are_rebuilt_as_train_py_exported_them(self):
        unet = seeded(UNet(inputs=6), 3).eval()
        prior = torch.tensor([0.5, 0.25, 0.25] + [0.0] * 9)
        record = {"settings": {"normals": True, "out": "run"}, "exported": {"tau": 0.5}}
        member, inputs = build_member(record, unet.state_dict(), "", prior)
        self.assertEqual(inputs, 6)
        x = torch.randn(1, 6, 32, 32)
        expected = unet(x)
        adjust = torch.cat([-0.5 * torch.log(prior[:3]), torch.full((9,), -30.0)])
        torch.testing.assert_close(member(x), expected + adjust[None, :, None, None], rtol=1e-4, atol=1e-4)
        with self.assertRaisesRegex(ValueError, "run was trained with a pretrained context encoder: pass --context"):
            build_member({"settings": {"context": "models", "out": "run"}, "exported": {"tau": 0}},
                         unet.state_dict(), "", prior)


class EnsembleToolTest(DatasetCase):
    def run_tool(self, *args):
        return subprocess.run([sys.executable, ENSEMBLE, *args], capture_output=True, text=True)

    def test_exports_one_model_with_the_members_validation_scores(self):
        first = seeded(UNet(inputs=6), 1).state_dict()
        runs = [os.path.join(self.tmp.name, f"run{i}") for i in range(3)]
        write_run(runs[0], self.dataset, first)
        write_run(runs[1], self.dataset, seeded(UNet(inputs=6), 2).state_dict(), tau=0.25)
        write_run(runs[2], self.dataset, first)  # the same weights twice: the exporter shares them (Identity)
        out = os.path.join(self.tmp.name, "out")
        done = self.run_tool(out, *runs)
        self.assertEqual(done.returncode, 0, done.stderr)
        with open(os.path.join(out, "training.json")) as f:
            record = json.load(f)
        scores = record["ensemble"]["validation_miou"]
        self.assertEqual(set(scores), set(runs) | {"ensemble"})
        self.assertEqual(record["ensemble"]["validation_images"], 4)  # 2 of 10 models, two views each
        self.assertEqual(len(record["members"]), 3)
        self.assertEqual(record["ensemble"]["int8_weights"]["convolutions"], 3 * 17)  # 18 per U-Net; the first (864 weights) stays float
        with open(os.path.join(out, "g2p-materials.json")) as f:
            card = json.load(f)
        self.assertEqual(card["input"]["channels"], ["rgb", "normal"])
        self.assertEqual((card["input"]["width"], card["output"]["kind"]), (32, "logits"))
        import onnx
        model = onnx.load(os.path.join(out, "g2p-materials.onnx"))
        constants = {t.name for t in model.graph.initializer}
        self.assertFalse([n.name for n in model.graph.node if n.op_type == "Identity" and n.input[0] in constants])
        if CLI is None:
            self.skipTest("no g2p CLI given: OpenCV's loading of the model not checked")
        views = os.path.join(self.tmp.name, "views")
        done = subprocess.run([CLI, "segment", os.path.join(ASSETS, "WaterBottle", "WaterBottle.glb"), "-o", views,
                               "--views", "1", "--resolution", "64", "--segmenter", "onnx", "--set",
                               "model_card=" + os.path.join(out, "g2p-materials.json")],
                              capture_output=True, text=True)
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertTrue(os.listdir(views))

    def test_a_failed_export_leaves_the_ensemble_it_would_replace(self):
        runs = [os.path.join(self.tmp.name, f"run{i}") for i in range(2)]
        for i, run in enumerate(runs):
            write_run(run, self.dataset, seeded(UNet(inputs=6), i + 1).state_dict())
        out = os.path.join(self.tmp.name, "out")
        done = self.run_tool(out, *runs)
        self.assertEqual(done.returncode, 0, done.stderr)
        first = snapshot(out)

        def failing_quantisation(model):
            raise RuntimeError("quantisation failed")

        argv, quantise = sys.argv, ensemble.quantize.quantize_conv_weights
        sys.argv, ensemble.quantize.quantize_conv_weights = [ENSEMBLE, out, runs[1], runs[0]], failing_quantisation
        try:
            with self.assertRaisesRegex(RuntimeError, "quantisation failed"):
                ensemble.main()
        finally:
            sys.argv, ensemble.quantize.quantize_conv_weights = argv, quantise
        self.assertEqual(snapshot(out), first)
        self.assertEqual(sorted(os.listdir(out)), ["g2p-materials.json", "g2p-materials.onnx", "training.json"])

    def test_an_ensemble_stands_for_its_members_and_one_of_them_can_be_continued(self):
        runs = [os.path.join(self.tmp.name, f"run{i}") for i in range(2)]
        for i, run in enumerate(runs):
            write_run(run, self.dataset, seeded(UNet(inputs=6), i + 1).state_dict(), tau=0.25 * i)
        out = os.path.join(self.tmp.name, "out")
        self.assertEqual(self.run_tool(out, *runs).returncode, 0)
        for name in ("best.pt", "training.json"):  # the runs are gone: only the ensemble's file is left
            os.remove(os.path.join(runs[0], name))
        bigger = os.path.join(self.tmp.name, "bigger")
        done = self.run_tool(bigger, out, runs[1])
        self.assertEqual(done.returncode, 0, done.stderr)
        with open(os.path.join(bigger, "training.json")) as f:
            record = json.load(f)
        self.assertEqual(record["ensemble"]["members"], [out + "#0", out + "#1", runs[1]])
        self.assertEqual([m["member"] for m in record["members"][:2]], [0, 1])
        self.assertEqual(record["ensemble"]["int8_weights"]["convolutions"], 3 * 17)
        one = os.path.join(self.tmp.name, "one")
        self.assertEqual(self.run_tool(one, out + "#0", runs[1]).returncode, 0)
        again = os.path.join(self.tmp.name, "again")  # an ensemble folder alone is exported again, both members
        done = self.run_tool(again, out)
        self.assertEqual(done.returncode, 0, done.stderr)
        with open(os.path.join(again, "training.json")) as f:
            self.assertEqual(json.load(f)["ensemble"]["members"], [out + "#0", out + "#1"])
        done = self.run_tool(os.path.join(self.tmp.name, "none"), out + "#2", runs[1])
        self.assertEqual(done.returncode, 2)
        self.assertIn("out#2: the ensemble has 2 members (#0 to #1)", done.stderr)

        # train.py continues one member of an ensemble's export, named PATH#K.
        exported = os.path.join(out, "g2p-materials.onnx")
        done = self.run_train(os.path.join(self.tmp.name, "whole"), "--epochs", "0", "--init", exported)
        self.assertEqual(done.returncode, 2)
        self.assertIn("an ensemble's export; name the member to start from as " + exported + "#K", done.stderr)
        continued = os.path.join(self.tmp.name, "continued")
        done = self.run_train(continued, "--epochs", "0", "--init", exported + "#1")
        self.assertEqual(done.returncode, 0, done.stderr)
        (_, member_record, _), = read_runs(out + "#1")
        member, _ = build_member(member_record, None, "", torch.zeros(12))
        x = torch.randn(1, 6, 32, 32)
        started = UNet(inputs=6)
        started.load_state_dict(onnx_weights.recover_state(started, os.path.join(continued, "g2p-materials.onnx"),
                                                           6, 32))
        with torch.no_grad():  # the run starts, and with no epochs ends, as the member (its adjustment included)
            expected = member(x)
            torch.testing.assert_close(started.eval()(x), expected, rtol=0, atol=1e-4 * expected.abs().max().item())
            other, _ = build_member(read_runs(out + "#0")[0][1], None, "", torch.zeros(12))
            # Member #0 is farther from it than ten times the tolerance: the check above can fail.
            self.assertGreater((other(x) - expected).abs().max().item(), 1e-3 * expected.abs().max().item())

    def test_members_validated_on_other_models_are_refused(self):
        state = seeded(UNet(inputs=6), 1).state_dict()
        a, b, c = (os.path.join(self.tmp.name, n) for n in ("a", "b", "c"))
        write_run(a, self.dataset, state)
        write_run(b, self.dataset, state, split_seed=2)
        write_run(c, self.dataset, state, sha="0" * 64)
        out = os.path.join(self.tmp.name, "out")
        done = self.run_tool(out, a, b)
        self.assertEqual(done.returncode, 2)
        self.assertRegex(done.stderr, r"b: validated on other models than .* \(split_seed differs\)")
        done = self.run_tool(out, a, c)
        self.assertRegex(done.stderr, r"c: validated on other models .* \(manifest differs\)")
        done = self.run_tool(out, a)
        self.assertRegex(done.stderr, "an ensemble needs at least two members; .*a has one")
        done = self.run_tool(out, a, os.path.join(self.tmp.name, "missing"))
        self.assertRegex(done.stderr, r"missing.training.json: not found")
        self.assertFalse(os.path.exists(out))  # nothing written on refusal


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
