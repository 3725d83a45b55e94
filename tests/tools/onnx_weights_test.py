#!/usr/bin/python3
"""tools/training/onnx_weights.py: a network's weights come back from its exported ONNX file (batch normalisation
folded in) so that it computes what the file computes, and calibrated batch normalisations make training mode start
there too; train.py --init and ensemble.py use it where a run's checkpoints are gone."""
import copy
import json
import os
import random
import sys
import tempfile
import unittest

import numpy as np
import torch

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", ".."))  # the repository root: tools.training is a package
sys.path.insert(0, HERE)
from tools.training import ensemble, onnx_weights, quantize, train  # noqa: E402
from tools.training.export import export_onnx, export_shape  # noqa: E402
from tools.training.model import ContextUNet, Ensemble, UNet  # noqa: E402
from tools.training.runs import build_member, read_runs  # noqa: E402
from train_test import DatasetCase, FakeContext, seeded, write_run  # noqa: E402


def trained_looking(model, seed):
    """`model` with random weights and random batch-normalisation statistics, as after training: folding them into
    the convolutions changes every weight."""
    seeded(model, seed)
    generator = torch.Generator().manual_seed(seed)
    with torch.no_grad():
        for m in model.modules():
            if isinstance(m, torch.nn.BatchNorm2d):
                m.running_mean.copy_(torch.randn(m.num_features, generator=generator) * 0.3)
                m.running_var.copy_(torch.rand(m.num_features, generator=generator) * 1.5 + 0.5)
                m.weight.copy_(torch.rand(m.num_features, generator=generator) + 0.5)
    return model.eval()


def context_network(seed, inputs=6):
    return trained_looking(ContextUNet(UNet(inputs=inputs), FakeContext(), trainable=True), seed)


def export(model, path, inputs=6, size=32):
    export_onnx(model, inputs, size, path)


def assert_same_function(got, expected, tolerance=1e-5):
    """Equal up to float32 rounding at the outputs' scale (the random networks' logits reach hundreds, and the export
    rounds differently where it folds a normalisation into a convolution)."""
    scale = expected.abs().max().item()
    torch.testing.assert_close(got, expected, rtol=0, atol=tolerance * scale)


def initializers_in_order(path):
    import onnx  # python3-onnx
    graph = onnx.load(path).graph
    values = onnx_weights._initializers(graph)
    return [values[name] for node in graph.node for name in node.input if name in values]


class RecoverTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.path = os.path.join(self.tmp.name, "g2p-materials.onnx")
        self.original = context_network(1)
        export(self.original, self.path)

    def tearDown(self):
        self.tmp.cleanup()

    def recovered(self):
        model = context_network(2)  # other weights: everything must come from the file
        model.load_state_dict(onnx_weights.recover_state(model, self.path, 6, 32))
        return model.eval()

    def test_the_recovered_network_computes_what_its_export_computes(self):
        model = self.recovered()
        x = torch.randn(2, 6, 32, 32)
        with torch.no_grad():
            expected, got = self.original(x), model(x)
            self.assertGreater((context_network(2)(x) - expected).abs().max().item(), 0.1 * expected.abs().max().item())
        assert_same_function(got, expected)
        again = os.path.join(self.tmp.name, "again.onnx")
        export(model, again)
        first, second = initializers_in_order(self.path), initializers_in_order(again)
        self.assertEqual(len(first), len(second))
        for a, b in zip(first, second):
            np.testing.assert_allclose(b, a, rtol=1e-6, atol=1e-7)
        # Folded batch normalisations come back as the identity with the folded bias as beta.
        bn = model.unet.enc[0][1]
        torch.testing.assert_close(bn.weight, torch.ones_like(bn.weight))
        torch.testing.assert_close(bn.running_mean, torch.zeros_like(bn.running_mean))

    def test_calibration_keeps_the_function_and_makes_training_mode_start_there(self):
        model = self.recovered()
        x = torch.randn(4, 6, 32, 32)
        with torch.no_grad():
            before = model(x)
            uncalibrated = copy.deepcopy(model).train()(x)
        # Batch statistics instead of the identity change everything.
        self.assertGreater((uncalibrated - before).abs().max().item(), 0.1 * before.abs().max().item())
        self.assertEqual(onnx_weights.calibrate_batch_norm(model, [x[:2], x[2:]]), 18)  # two per U-Net block
        self.assertFalse(model.training)
        with torch.no_grad():
            after = model(x)
            in_training = copy.deepcopy(model).train()(x)
        assert_same_function(after, before)
        # On the batch it was calibrated on, training mode (batch statistics) computes the export's function.
        assert_same_function(in_training, before, 1e-4)
        bn = model.unet.enc[0][1]
        self.assertGreater((bn.running_var - 1).abs().max().item(), 1e-3)

    def test_starting_from_an_export_leaves_the_random_generators_as_they_were(self):
        def batches():  # draws from the three generators, as the training loader's shuffling and augmentations do
            while True:
                random.random()
                np.random.rand()
                yield torch.randn(2, 6, 32, 32), None

        def next_draws():
            return random.random(), float(np.random.rand()), torch.rand(1).item()

        def seed():
            random.seed(5)
            np.random.seed(5)
            torch.manual_seed(5)

        seed()
        untouched = next_draws()
        seed()
        for _ in zip(range(8), batches()):
            pass
        self.assertNotEqual(next_draws(), untouched)  # the calibration batches do move all three generators
        model = context_network(2)  # seeds torch itself
        seed()
        self.assertEqual(train.init_from_export(model, self.path, 6, batches()), 18)
        # A run from an export sees the batches and augmentations the same run from a checkpoint sees.
        self.assertEqual(next_draws(), untouched)

    def test_files_that_are_not_this_networks_export_are_refused(self):
        other = os.path.join(self.tmp.name, "rgb.onnx")
        export(context_network(3, inputs=3), other, inputs=3)
        with self.assertRaisesRegex(ValueError, "rgb.onnx: not this network's export"):
            onnx_weights.recover_state(context_network(2), other, 6, 32)
        unet = os.path.join(self.tmp.name, "unet.onnx")
        export(trained_looking(UNet(inputs=6), 3), unet)
        with self.assertRaisesRegex(ValueError, "unet.onnx: not this network's export"):
            onnx_weights.recover_state(context_network(2), unet, 6, 32)
        text = os.path.join(self.tmp.name, "text.onnx")
        with open(text, "w") as f:
            f.write("not a model")
        with self.assertRaisesRegex(ValueError, "text.onnx: not an ONNX file"):
            onnx_weights.recover_state(context_network(2), text, 6, 32)
        with self.assertRaisesRegex(ValueError, "text.onnx: not an ONNX file"):
            export_shape(text)
        self.assertEqual(export_shape(other), (3, 32))


class EnsembleRecoverTest(unittest.TestCase):
    """An ensemble.py export (members side by side, Identity constants inlined, convolutions in int8) comes apart
    into its members' weights: exported again, they give the same file."""

    def test_the_members_come_back_with_the_rounded_weights(self):
        self.check_members_come_back("logits")

    def test_members_of_an_older_export_averaging_log_softmax_come_back(self):
        self.check_members_come_back("log_softmax")

    def check_members_come_back(self, combine):
        import onnx  # python3-onnx
        from onnx import numpy_helper
        originals = [context_network(1), context_network(2)]
        with tempfile.TemporaryDirectory() as tmp:
            path, again = os.path.join(tmp, "ensemble.onnx"), os.path.join(tmp, "again.onnx")
            quantised = ensemble.export_ensemble(Ensemble(originals, combine).eval(), 6, 32, path)
            self.assertEqual(onnx_weights.combine_of(path), combine)
            self.assertGreater(quantised["convolutions"], 30)
            states = onnx_weights.recover_members([context_network(3), context_network(4)], path, 6, 32)
            self.assertEqual(len(states), 2)
            members = []
            for state in states:
                member = context_network(5)
                member.load_state_dict(state)
                members.append(member.eval())
            x = torch.randn(2, 6, 32, 32)
            for k, (original, member) in enumerate(zip(originals, members)):
                # Each member alone, in int8, read back as one network: the same rounded weights by another path.
                alone = os.path.join(tmp, f"alone{k}.onnx")
                export(original, alone)
                model = onnx.load(alone)
                quantize.quantize_conv_weights(model)
                onnx.save(model, alone)
                rounded = context_network(6)
                rounded.load_state_dict(onnx_weights.recover_state(rounded, alone, 6, 32))
                with torch.no_grad():
                    expected, got = original(x), member(x)
                    self.assertGreater((got - expected).abs().max().item(), 0)  # the weights were rounded to 8 bits
                    assert_same_function(got, rounded.eval()(x))
                    self.assertGreater((members[1 - k](x) - got).abs().max().item(), 0.1 * expected.abs().max().item())
            # Exported again as ensemble.py exports, the recovered members give the file they came from.
            ensemble.export_ensemble(Ensemble(members, combine).eval(), 6, 32, again)
            first, second = onnx.load(path).graph, onnx.load(again).graph
            with self.assertRaisesRegex(ValueError, "not this network's export .*an ensemble read as one network"):
                onnx_weights.recover_state(context_network(3), path, 6, 32)
        self.assertEqual([n.op_type for n in first.node], [n.op_type for n in second.node])
        ints = 0
        for a, b in zip(first.initializer, second.initializer):
            a, b = numpy_helper.to_array(a), numpy_helper.to_array(b)
            if a.dtype == np.int8:
                ints += 1
                np.testing.assert_array_equal(b, a)
            else:
                np.testing.assert_allclose(b, a, rtol=1e-5, atol=1e-6)
        self.assertEqual(ints, quantised["convolutions"])


class ContinueFromExportTest(DatasetCase):
    def test_train_starts_from_an_exported_network(self):
        first = os.path.join(self.tmp.name, "first")
        done = self.run_train(first, "--epochs", "1", "--batch", "8")
        self.assertEqual(done.returncode, 0, done.stderr)
        exported = os.path.join(first, "g2p-materials.onnx")
        os.remove(os.path.join(first, "best.pt"))
        os.remove(os.path.join(first, "checkpoint.pt"))
        # No training steps: the new run exports the network it started from.
        second = os.path.join(self.tmp.name, "second")
        done = self.run_train(second, "--epochs", "0", "--init", exported)
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertRegex(done.stdout, r"weights recovered, 18 batch normalisations calibrated")
        before, after = initializers_in_order(exported), initializers_in_order(os.path.join(second,
                                                                                             "g2p-materials.onnx"))
        self.assertEqual(len(before), len(after))
        for a, b in zip(before, after):
            np.testing.assert_allclose(b, a, rtol=1e-4, atol=1e-5)
        done = self.run_train(os.path.join(self.tmp.name, "third"), "--epochs", "0", "--init", exported,
                              "--context", self.tmp.name)
        self.assertEqual(done.returncode, 2)
        self.assertIn("no nanodet.json", done.stderr)
        rgb = [a for a in self.train_args(os.path.join(self.tmp.name, "fourth"), "--epochs", "0", "--init", exported)
               if a != "--normals"]
        import subprocess
        done = subprocess.run([sys.executable, train.__file__, *rgb], capture_output=True, text=True)
        self.assertEqual(done.returncode, 2)
        self.assertIn("takes 6 input channels, this network 3 (--normals?)", done.stderr)


class EnsembleMemberFromExportTest(DatasetCase):
    def test_a_run_without_checkpoints_joins_through_its_export(self):
        state = trained_looking(UNet(inputs=6), 4).state_dict()
        run = os.path.join(self.tmp.name, "run")
        write_run(run, self.dataset, state, tau=0.25)
        prior = torch.tensor([0.5, 0.25, 0.25] + [0.0] * 9)
        record, loaded = read_runs(run)[0][1:]
        reference, _ = build_member(record, loaded, "", prior)
        export(reference, os.path.join(run, "g2p-materials.onnx"))
        os.remove(os.path.join(run, "best.pt"))
        record, loaded = read_runs(run)[0][1:]
        self.assertIsNone(loaded)
        self.assertEqual(record["weights_from"], os.path.join(os.path.abspath(run), "g2p-materials.onnx"))
        member, inputs = build_member(record, loaded, "", prior)
        self.assertEqual(inputs, 6)
        x = torch.randn(1, 6, 32, 32)
        with torch.no_grad():  # the adjustment (tau 0.25) is in the export once, and not added again
            assert_same_function(member(x), reference(x))
        with self.assertRaisesRegex(ValueError, r"logit adjustment \(tau 0.25\) is folded into the weights"):
            build_member(record, None, "", None)  # a teacher needs the network before it
        os.remove(os.path.join(run, "g2p-materials.onnx"))
        with self.assertRaisesRegex(ValueError, "holds neither best.pt nor g2p-materials.onnx"):
            read_runs(run)
        with self.assertRaisesRegex(ValueError, r"run#1: .*run is one network, not an ensemble \(drop #1\)"):
            read_runs(run + "#1")
        with open(os.path.join(run, "training.json"), "w") as f:
            json.dump({"ensemble": {}, "members": []}, f)
        with self.assertRaisesRegex(ValueError, "an ensemble without members"):
            read_runs(run)


if __name__ == "__main__":
    unittest.main()
