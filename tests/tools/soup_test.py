#!/usr/bin/python3
"""tools/training/soup.py: the soup's weights are the members' mean (before their logit adjustment), batch
normalisation statistics can be recomputed through the averaged layers, the chosen variant and tau are the best on
validation, the output folder serves as a run (ensemble.py reads it), and members that cannot be averaged are refused
without writing anything."""
import json
import os
import subprocess
import sys
import unittest

import torch
import torch.nn as nn

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", ".."))  # the repository root: tools.training is a package
sys.path.insert(0, HERE)
from tools.training import soup  # noqa: E402
from tools.training.model import UNet  # noqa: E402
from tools.training.runs import build_member, read_runs  # noqa: E402
from train_test import DatasetCase, seeded, snapshot, write_run  # noqa: E402

SOUP = os.path.join(HERE, "..", "..", "tools", "training", "soup.py")


def with_statistics(module, seed):
    """`module` with random batch normalisation statistics (a trained network's are not 0 and 1)."""
    generator = torch.Generator().manual_seed(seed)
    for m in module.modules():
        if isinstance(m, nn.BatchNorm2d):
            m.running_mean.copy_(torch.randn(m.num_features, generator=generator))
            m.running_var.copy_(torch.rand(m.num_features, generator=generator) + 0.5)
            m.num_batches_tracked.fill_(seed)
    return module


class AverageTest(unittest.TestCase):
    def test_the_soup_is_the_element_wise_mean(self):
        a, b = (with_statistics(seeded(UNet(inputs=6), s), s).state_dict() for s in (1, 2))
        mean = soup.average_states([a, b])
        self.assertEqual(list(mean), list(a))
        for key in a:
            if a[key].is_floating_point():
                self.assertFalse(torch.equal(a[key], b[key]), key)  # the members differ: the check can fail
                torch.testing.assert_close(mean[key], (a[key] + b[key]) / 2, rtol=0, atol=1e-7)
            else:
                self.assertEqual(int(mean[key]), int(a[key]), key)
        same = soup.average_states([a, a, a])
        for key in a:
            self.assertTrue(torch.equal(same[key], a[key]), key)  # one network averaged with itself is itself

    def test_other_architectures_are_refused(self):
        rgb, normals = (seeded(UNet(inputs=n), 1).state_dict() for n in (3, 6))
        with self.assertRaisesRegex(ValueError, r"enc.0.0.weight: the members' shapes differ \(\(16, 6, 3, 3\), "
                                                r"\(16, 3, 3, 3\)\)"):
            soup.average_states([normals, rgb])
        fewer = dict(normals)
        del fewer["head.bias"]
        with self.assertRaisesRegex(ValueError, "member 1 has other weights than member 0"):
            soup.average_states([normals, fewer])

    def test_recomputed_statistics_are_those_of_the_inputs_in_training_mode(self):
        net = with_statistics(seeded(UNet(inputs=3), 3), 7)
        batches = [torch.randn(4, 3, 16, 16) * 2 + 1 for _ in range(3)]
        first_conv, first_bn = net.enc[0][0], net.enc[0][1]
        with torch.no_grad():
            features = torch.cat([first_conv(x) for x in batches])  # what the first normalisation sees
        expected_mean = features.mean((0, 2, 3))
        expected_var = features.var((0, 2, 3), unbiased=True)
        self.assertGreater((first_bn.running_mean - expected_mean).abs().max().item(), 0.1)  # stale before
        momentum = first_bn.momentum
        net.eval()
        bns = sum(isinstance(m, nn.BatchNorm2d) for m in net.modules())
        self.assertEqual(soup.recompute_batch_norm(net, batches), bns)
        torch.testing.assert_close(first_bn.running_mean, expected_mean, rtol=0, atol=1e-5)
        # The cumulative average of per-batch unbiased variances, close to (not equal to) the pooled variance.
        torch.testing.assert_close(first_bn.running_var, expected_var, rtol=0.1, atol=1e-3)
        self.assertEqual(first_bn.momentum, momentum)
        self.assertFalse(net.training)  # left in the mode it was in


class SoupToolTest(DatasetCase):
    def run_tool(self, *args):
        return subprocess.run([sys.executable, SOUP, *args, "--threads", "1"], capture_output=True, text=True)

    def runs(self, count=2, **kwargs):
        paths = []
        for i in range(count):
            path = os.path.join(self.tmp.name, f"run{i}")
            state = with_statistics(seeded(UNet(inputs=6), i + 1), i + 1).state_dict()
            write_run(path, self.dataset, state, tau=0.25 * i, **kwargs)
            paths.append(path)
        return paths

    def test_writes_a_run_of_the_averaged_weights(self):
        runs = self.runs()
        out = os.path.join(self.tmp.name, "soup")
        done = self.run_tool(out, *runs, "--bn", "average")
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertIn("members as exported: 50.0, 50.0 %", done.stdout)
        states = [torch.load(os.path.join(r, "best.pt")) for r in runs]
        written = torch.load(os.path.join(out, "best.pt"))
        expected = {k: (v + states[1][k]) / 2 if v.is_floating_point() else v for k, v in states[0].items()}
        self.assertEqual(list(written), list(expected))
        for key in expected:
            torch.testing.assert_close(written[key], expected[key], rtol=0, atol=1e-7, msg=key)
        with open(os.path.join(out, "training.json")) as f:
            record = json.load(f)
        self.assertEqual(record["soup"]["members"], runs)
        self.assertEqual(record["soup"]["batch_norm"], "average")
        scores = record["soup"]["validation_miou"]["average"]
        self.assertEqual(record["exported"]["val_miou"], max(scores.values()))
        self.assertEqual(scores[str(record["exported"]["tau"])], record["exported"]["val_miou"])
        self.assertEqual(record["settings"]["out"], out)

        # The folder is a run: ensemble.py rebuilds it with its tau folded in, as train.py would have exported it.
        (_, member_record, state), = read_runs(out)
        prior = torch.tensor([0.2, 0.8] + [0.0] * 10)
        member, _ = build_member(member_record, state, "", prior)
        plain = UNet(inputs=6)
        plain.load_state_dict(expected)
        x = torch.randn(1, 6, 32, 32)
        tau = record["exported"]["tau"]
        adjust = torch.where(prior > 0, -tau * torch.log(prior.clamp(min=1e-12)), torch.full_like(prior, -30.0))
        with torch.no_grad():
            torch.testing.assert_close(member(x), plain.eval()(x) + adjust[None, :, None, None], rtol=1e-4, atol=1e-4)
        import onnx  # the export loads and its classifier bias is the soup's with the adjustment folded in
        exported = onnx.load(os.path.join(out, "g2p-materials.onnx"))
        self.assertIn("logits", [o.name for o in exported.graph.output])

    def test_both_statistics_are_tried_and_the_better_kept(self):
        runs = self.runs()
        out = os.path.join(self.tmp.name, "soup")
        done = self.run_tool(out, *runs, "--bn-batches", "2")
        self.assertEqual(done.returncode, 0, done.stderr)
        with open(os.path.join(out, "training.json")) as f:
            record = json.load(f)
        scores = record["soup"]["validation_miou"]
        self.assertEqual(set(scores), {"average", "recompute"})
        best = max(max(s.values()) for s in scores.values())
        self.assertEqual(record["exported"]["val_miou"], best)
        self.assertEqual(max(scores[record["soup"]["batch_norm"]].values()), best)
        written = torch.load(os.path.join(out, "best.pt"))
        averaged = soup.average_states([torch.load(os.path.join(r, "best.pt")) for r in runs])
        key = "enc.0.1.running_mean"
        kept_average = torch.equal(written[key], averaged[key])
        self.assertEqual(kept_average, record["soup"]["batch_norm"] == "average")
        self.assertTrue(torch.equal(written["enc.0.0.weight"], averaged["enc.0.0.weight"]))  # weights averaged alike

    def test_members_that_cannot_be_averaged_are_refused_and_nothing_is_written(self):
        runs = self.runs()
        other_split = os.path.join(self.tmp.name, "other_split")
        write_run(other_split, self.dataset, torch.load(os.path.join(runs[0], "best.pt")), split_seed=2)
        rgb = os.path.join(self.tmp.name, "rgb")
        write_run(rgb, self.dataset, seeded(UNet(inputs=3), 1).state_dict())
        with open(os.path.join(rgb, "training.json")) as f:
            record = json.load(f)
        record["settings"]["normals"] = False
        with open(os.path.join(rgb, "training.json"), "w") as f:
            json.dump(record, f)
        out = os.path.join(self.tmp.name, "soup")
        done = self.run_tool(out, runs[0], other_split)
        self.assertEqual(done.returncode, 2)
        self.assertRegex(done.stderr, r"other_split: validated on other models than .*run0 \(split_seed differs\)")
        done = self.run_tool(out, runs[0], rgb)
        self.assertRegex(done.stderr, r"rgb: normals differ from .*run0's; only one architecture averages")
        done = self.run_tool(out, runs[0])
        self.assertRegex(done.stderr, "a soup needs at least two members; .*run0 has one")
        self.assertFalse(os.path.exists(out))
        # An OUT holding a run is kept unless --overwrite.
        self.assertEqual(self.run_tool(out, *runs, "--bn", "average").returncode, 0)
        before = snapshot(out)
        done = self.run_tool(out, *runs, "--bn", "average")
        self.assertEqual(done.returncode, 2)
        self.assertIn("already holds a run", done.stderr)
        self.assertEqual(snapshot(out), before)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
