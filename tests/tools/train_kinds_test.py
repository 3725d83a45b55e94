#!/usr/bin/python3
"""tools/training/train_kinds.py, the kind classifier's head and calibration, on synthetic features: the head
separates classes it can separate, the two fusions of views behave as documented, the temperature is found where
the data put it, Platt scaling turns modest confidences into calibrated ones, and the reliability diagram and its
error are what they say; the shape head learns what the cues tell, earns its weight in the join only when they
tell something, and reaches the card exactly."""
import json
import math
import os
import sys
import unittest

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", ".."))  # the repository root: tools.training is a package
from tools.training import train_kinds  # noqa: E402


def clusters(n_per_class, classes, dim, spread, seed):
    rng = np.random.default_rng(seed)
    centres = rng.normal(size=(classes, dim)) * 3
    x = np.concatenate([centres[c] + spread * rng.normal(size=(n_per_class, dim)) for c in range(classes)])
    y = np.repeat(np.arange(classes), n_per_class)
    return x.astype(np.float32), y.astype(np.int64)


class HeadTest(unittest.TestCase):
    def test_the_head_separates_separable_classes_and_weights_count(self):
        x, y = clusters(40, 5, 16, 0.5, 0)
        w = np.ones(len(y), dtype=np.float32)
        head = train_kinds.train_head(x, y, w, 5, 1e-4, 100)
        import torch
        with torch.no_grad():
            predicted = head(torch.from_numpy(x)).argmax(1).numpy()
        self.assertGreater((predicted == y).mean(), 0.97)
        # A class whose examples weigh nothing is not learnt: its examples go to the others.
        w[y == 2] = 0.0
        head = train_kinds.train_head(x, y, w, 5, 1e-4, 100)
        with torch.no_grad():
            predicted = head(torch.from_numpy(x)).argmax(1).numpy()
        self.assertLess((predicted[y == 2] == 2).mean(), 0.5)


class FusionTest(unittest.TestCase):
    def test_mean_and_geometric_fusion(self):
        z = np.array([[4.0, 0.0, 0.0], [0.0, 4.0, 0.0]])  # two views that disagree
        mean = train_kinds.fuse(z, 1.0, "mean")
        geometric = train_kinds.fuse(z, 1.0, "geometric")
        for p in (mean, geometric):
            self.assertAlmostEqual(p.sum(), 1.0, places=6)
        self.assertAlmostEqual(mean[0], mean[1], places=6)
        self.assertAlmostEqual(geometric[0], geometric[1], places=6)
        # Views that agree on the kind but not on how sure: the geometric mean is the sharper (softmax of the mean
        # logits [3, 0, 0]: 0.909; the mean of 0.965 and 0.787: 0.876).
        agree = np.array([[4.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
        self.assertAlmostEqual(train_kinds.fuse(agree, 1.0, "geometric")[0], math.exp(3) / (math.exp(3) + 2), places=6)
        self.assertGreater(train_kinds.fuse(agree, 1.0, "geometric")[0], train_kinds.fuse(agree, 1.0, "mean")[0])
        # A higher temperature flattens.
        self.assertLess(train_kinds.fuse(z, 5.0, "mean").max(), mean.max())


class CalibrationTest(unittest.TestCase):
    def test_the_temperature_is_found_where_the_data_put_it(self):
        # Logits drawn so that the true class's probability is right at temperature 2.
        rng = np.random.default_rng(1)
        logits, truth = {}, {}
        for m in range(400):
            z = rng.normal(size=(1, 6)) * 4
            p = np.exp(z[0] / 2.0)
            p /= p.sum()
            logits[m], truth[m] = z, int(rng.choice(6, p=p))
        t = train_kinds.fit_temperature(logits, truth, "mean")
        self.assertGreater(t, 1.5)
        self.assertLess(t, 2.7)

    def test_platt_scaling_makes_modest_confidences_honest(self):
        # The top kind is right with probability 3c (capped): confidences far too modest.
        rng = np.random.default_rng(2)
        c = rng.uniform(0.02, 0.3, 3000)
        right = rng.uniform(size=c.size) < np.minimum(3 * c, 0.95)
        ab = train_kinds.fit_platt(list(c), list(right))
        self.assertGreater(ab[0], 0)
        calibrated = [train_kinds.platt(v, ab) for v in c]
        before = train_kinds.reliability(list(c), list(right))[1]
        after = train_kinds.reliability(calibrated, list(right))[1]
        self.assertGreater(before, 0.15)
        self.assertLess(after, 0.05)
        # Monotone: the ranking of kinds does not change.
        self.assertTrue(all(a <= b for a, b in zip(sorted(calibrated), [train_kinds.platt(v, ab) for v in sorted(c)])))

    def test_the_reliability_diagram(self):
        rows, ece = train_kinds.reliability([0.05, 0.15, 0.95, 1.0], [False, True, True, True], bins=10)
        self.assertEqual([r["models"] for r in rows], [1, 1, 2])
        self.assertAlmostEqual(rows[1]["right"], 1.0)
        self.assertAlmostEqual(rows[2]["mean_confidence"], 0.975)
        expected = (0.05 + (1 - 0.15) + (1 - 0.975) * 2) / 4
        self.assertAlmostEqual(ece, expected, places=6)
        self.assertTrue(math.isfinite(train_kinds.logit(0.0)))


class ShapeHeadTest(unittest.TestCase):
    def test_a_shape_head_learns_what_the_views_cannot_tell_and_earns_its_weight(self):
        # Two classes the views confuse (50/50) but the cues separate: the shape head learns them, and the
        # weight that best explains held-out truths is clearly above 0; with cues of noise it stays near 0.
        rng = np.random.default_rng(1)
        z, y = clusters(60, 3, 13, 0.7, 2)
        w = np.ones(len(y), dtype=np.float32)
        head = train_kinds.train_shape_head(z, y, w, 3, 32, 1e-3)
        self.assertGreater(np.mean([np.argmax(train_kinds.shape_logp(head, v)) == c for v, c in zip(z, y)]), 0.95)
        linear = train_kinds.train_shape_head(z, y, w, 3, 0, 1e-3)
        self.assertEqual(len(linear.layers), 1)
        held, truth = clusters(20, 3, 13, 0.7, 2)
        views = {i: np.array([0.45, 0.45, 0.10]) if c < 2 else np.array([0.1, 0.1, 0.8]) for i, c in enumerate(truth)}
        shapes = {i: train_kinds.shape_logp(head, v) for i, v in enumerate(held)}
        weight = train_kinds.fit_shape_weight(views, shapes, dict(enumerate(truth)))
        self.assertGreater(weight, 0.3)
        noise = {i: train_kinds.shape_logp(head, v) for i, v in enumerate(rng.normal(size=(len(truth), 13)) * 3)}
        self.assertLess(train_kinds.fit_shape_weight(views, noise, dict(enumerate(truth))), weight / 2)
        joined = train_kinds.join(views[0], shapes[0], weight)
        self.assertAlmostEqual(joined.sum(), 1.0, places=9)
        self.assertIs(train_kinds.join(views[0], None, weight), views[0])

    def test_the_card_keeps_the_shape_heads_weights_exactly_and_lists_on_one_line(self):
        z, y = clusters(10, 3, 13, 0.5, 3)
        head = train_kinds.train_shape_head(z, y, np.ones(len(y), dtype=np.float32), 3, 4, 1e-3, iterations=20)
        card = {"format": "g2p-kind-classifier-card", "input": {"shape": [1, 3, 224, 224]},
                "shape": train_kinds.shape_card(head, [f"c{i}" for i in range(13)], np.zeros(13), np.ones(13), 0.25)}
        text = train_kinds.card_text(card)
        self.assertIn('"shape": [1, 3, 224, 224]', text)
        back = json.loads(text)["shape"]
        self.assertEqual([layer["activation"] for layer in back["layers"]], ["tanh", "none"])
        first = head.layers[0].weight.detach().numpy()
        self.assertEqual(np.array(back["layers"][0]["weights"], dtype=np.float32).tolist(), first.tolist())
        self.assertEqual(len(back["layers"][1]["bias"]), 3)


if __name__ == "__main__":
    unittest.main()
