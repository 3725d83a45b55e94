#!/usr/bin/python3
"""tools/training/train.py's networks: ContextUNet starts as the U-Net it is given, feeds its encoder NanoDet's
normalisation, learns only what it should, and checkpoints load into the right part (load_init)."""
import os
import sys
import unittest

import torch
import torch.nn as nn
import torch.nn.functional as F

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools", "training"))
import train  # noqa: E402


class FakeContext(nn.Module):
    """Stands in for NanoDet-g: 128-channel maps at strides 8, 16 and 32 of its input (or others, to test the
    check). It records the last input it saw."""

    def __init__(self, strides=(8, 16, 32)):
        super().__init__()
        self.strides = strides
        self.proj = nn.Conv2d(3, 128, 1)
        self.seen = None

    def forward(self, x):
        self.seen = x
        return [self.proj(F.avg_pool2d(x, s)) for s in self.strides]


def seeded(module, seed):
    torch.manual_seed(seed)
    for p in module.parameters():
        nn.init.normal_(p, 0, 0.1)
    return module


class ContextUNetTest(unittest.TestCase):
    def test_starts_as_its_unet_and_learns_the_injection_only(self):
        unet = seeded(train.UNet(inputs=6), 1).eval()
        model = train.ContextUNet(unet, FakeContext()).eval()
        x = torch.randn(2, 6, 64, 64)
        with torch.no_grad():
            self.assertLess(float((model(x) - unet(x)).abs().max()), 1e-6)
        # The encoder saw the RGB channels at twice the size.
        self.assertEqual(tuple(model.context.seen.shape), (2, 3, 128, 128))
        model.train()
        model(x).sum().backward()
        self.assertTrue(all(p.grad is None for p in model.context.parameters()))  # frozen
        self.assertTrue(all(p.grad is None for p in model.to_context.parameters()))  # fixed
        self.assertTrue(all(p.grad is not None and p.grad.abs().sum() > 0 for p in model.inject.parameters()))

    def test_feeds_the_encoder_nanodets_normalisation(self):
        model = train.ContextUNet(train.UNet(inputs=3), FakeContext())
        rgb = torch.rand(1, 3, 4, 4)
        ours = (rgb - torch.tensor(train.MEAN)[:, None, None]) / torch.tensor(train.STD)[:, None, None]
        bgr255 = rgb.flip(1) * 255
        expected = (bgr255 - torch.tensor(train.CONTEXT_MEAN)[:, None, None]) / torch.tensor(train.CONTEXT_STD)[:, None, None]
        with torch.no_grad():
            self.assertLess(float((model.to_context(ours) - expected).abs().max()), 1e-4)

    def test_a_trainable_encoder_gets_gradients(self):
        model = train.ContextUNet(train.UNet(inputs=3), FakeContext(), trainable=True)
        nn.init.normal_(model.inject[0].weight, 0, 0.1)  # so that the encoder's output matters
        model(torch.randn(1, 3, 64, 64)).sum().backward()
        self.assertTrue(model.context.proj.weight.grad.abs().sum() > 0)

    def test_an_encoder_with_other_strides_is_refused(self):
        with self.assertRaisesRegex(ValueError, "strides 8, 16, 32"):
            train.ContextUNet(train.UNet(inputs=3), FakeContext(strides=(4, 8, 16)))


class LoadInitTest(unittest.TestCase):
    def test_an_rgb_unet_starts_the_unet_part_and_grows_normal_inputs(self):
        rgb_net = seeded(train.UNet(inputs=3), 2).eval()
        model = train.ContextUNet(train.UNet(inputs=6), FakeContext()).eval()
        train.load_init(model, rgb_net.state_dict())
        x = torch.randn(1, 6, 64, 64)
        with torch.no_grad():
            # The normals' weights are zero: the network is the RGB one.
            self.assertLess(float((model(x) - rgb_net(x[:, :3])).abs().max()), 1e-5)
        self.assertEqual(float(model.unet.enc[0][0].weight[:, 3:].abs().sum()), 0.0)

    def test_a_context_checkpoint_restores_the_whole_network(self):
        source = train.ContextUNet(seeded(train.UNet(inputs=6), 3), FakeContext())
        nn.init.normal_(source.inject[1].weight, 0, 0.1)
        target = train.ContextUNet(train.UNet(inputs=6), FakeContext())
        train.load_init(target, source.state_dict())
        for (k, a), b in zip(source.state_dict().items(), target.state_dict().values()):
            self.assertTrue(torch.equal(a, b), k)

    def test_mismatches_say_what_to_do(self):
        context_state = train.ContextUNet(train.UNet(inputs=3), FakeContext()).state_dict()
        with self.assertRaisesRegex(ValueError, "ctx.pt .*--context"):
            train.load_init(train.UNet(inputs=3), context_state, "ctx.pt")
        with self.assertRaisesRegex(ValueError, "other.pt is not a checkpoint"):
            train.load_init(train.UNet(inputs=3), {"weight": torch.zeros(1)}, "other.pt")


if __name__ == "__main__":
    unittest.main()
