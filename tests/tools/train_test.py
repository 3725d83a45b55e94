#!/usr/bin/python3
"""tools/training/train.py's networks: ContextUNet starts as the U-Net it is given, feeds its encoder NanoDet's
normalisation, learns only what it should, and checkpoints load into the right part (load_init); datasets of
the same models rendered with other seeds join the training set without leaking validation models
(training_rows, Dataset)."""
import csv
import gzip
import hashlib
import json
import math
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

import torch
import torch.nn as nn
import torch.nn.functional as F

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))  # the repository root: tools.training is a package
from tools.training import train  # noqa: E402
from tools.training.data import (CLASSES, MEAN, STD, UNLABELLED_OBJECT, Dataset, augment, read_manifest,  # noqa: E402
                                 training_rows, validation_subsample)
from tools.training.export import RUN_FILES, staged_export  # noqa: E402
from tools.training.model import ContextUNet, Ensemble, UNet, load_init  # noqa: E402

TRAIN = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools", "training", "train.py")


class FakeContext(nn.Module):
    """Stands in for NanoDet-g: 128-channel (or `channels`) maps at strides 8, 16 and 32 of its input (or others, to test the
    check). It records the last input it saw."""

    def __init__(self, strides=(8, 16, 32), channels=128):
        super().__init__()
        self.strides = strides
        self.proj = nn.Conv2d(3, channels, 1)
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
        unet = seeded(UNet(inputs=6), 1).eval()
        model = ContextUNet(unet, FakeContext()).eval()
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
        model = ContextUNet(UNet(inputs=3), FakeContext())
        rgb = torch.rand(1, 3, 4, 4)
        ours = (rgb - torch.tensor(MEAN)[:, None, None]) / torch.tensor(STD)[:, None, None]
        bgr255 = rgb.flip(1) * 255
        expected = (bgr255 - torch.tensor([103.53, 116.28, 123.675])[:, None, None]) / torch.tensor(
            [57.375, 57.12, 58.395])[:, None, None]
        with torch.no_grad():
            self.assertLess(float((model.to_context(ours) - expected).abs().max()), 1e-4)
        # MobileNetV2 (Keras) takes RGB scaled to -1..1.
        mobile = ContextUNet(UNet(inputs=3), FakeContext(), kind="mobilenet_v2")
        with torch.no_grad():
            self.assertLess(float((mobile.to_context(ours) - (rgb * 2 - 1)).abs().max()), 1e-4)

    def test_a_trainable_encoder_gets_gradients(self):
        model = ContextUNet(UNet(inputs=3), FakeContext(), trainable=True)
        nn.init.normal_(model.inject[0].weight, 0, 0.1)  # so that the encoder's output matters
        model(torch.randn(1, 3, 64, 64)).sum().backward()
        self.assertTrue(model.context.proj.weight.grad.abs().sum() > 0)

    def test_an_encoder_with_other_strides_is_refused(self):
        with self.assertRaisesRegex(ValueError, "strides 8, 16, 32"):
            ContextUNet(UNet(inputs=3), FakeContext(strides=(4, 8, 16)))
        with self.assertRaisesRegex(ValueError, "strides 8, 16, 32"):
            ContextUNet(UNet(inputs=3), FakeContext(), extra=[(FakeContext(strides=(8, 16)), "nanodet")])

    def test_an_extra_encoder_starts_at_zero_and_learns_its_injection(self):
        first = ContextUNet(seeded(UNet(inputs=6), 4), FakeContext())
        nn.init.normal_(first.inject[0].weight, 0, 0.1)
        extra = FakeContext(channels=32)
        model = ContextUNet(UNet(inputs=6), FakeContext(), kind="nanodet",
                            extra=[(extra, "mobilenet_v2")])
        load_init(model, first.state_dict())  # a checkpoint without the extra encoder
        first.eval(), model.eval()
        x = torch.randn(2, 6, 64, 64)
        with torch.no_grad():
            self.assertLess(float((model(x) - first(x)).abs().max()), 1e-6)
        # The extra encoder saw its own normalisation of the RGB channels (-1..1), upsampled as the first.
        rgb = x[:, :3] * torch.tensor(STD)[:, None, None] + torch.tensor(MEAN)[:, None, None]
        seen = F.interpolate(rgb * 2 - 1, scale_factor=2, mode="bilinear", align_corners=False)
        self.assertLess(float((extra.seen - seen).abs().max()), 1e-4)
        self.assertEqual([c.in_channels for c in model.extra[0].inject], [32, 32, 32])
        model.train()
        model(x).sum().backward()
        self.assertTrue(all(p.grad is None for p in extra.parameters()))  # frozen, as the first
        self.assertTrue(all(p.grad is not None and p.grad.abs().sum() > 0 for p in model.extra[0].inject.parameters()))
        self.assertEqual({id(p) for p in model.pretrained_parameters()},
                         {id(p) for p in list(model.context.parameters()) + list(extra.parameters())})
        # Building the extra encoder draws nothing from the generator: a run with it sees the same batches.
        draws = []
        for extra in ([], [(FakeContext(channels=32), "mobilenet_v2")]):
            unet, context = UNet(inputs=6), FakeContext()
            torch.manual_seed(11)
            ContextUNet(unet, context, extra=extra)
            draws.append(torch.rand(3))
        self.assertTrue(torch.equal(draws[0], draws[1]))
        # A checkpoint with the extra encoder does not load into a network without it.
        with self.assertRaisesRegex(ValueError, "ctx.pt does not fit this network.*unexpected.*extra"):
            load_init(ContextUNet(UNet(inputs=6), FakeContext()), model.state_dict(), "ctx.pt")


class LoadInitTest(unittest.TestCase):
    def test_an_rgb_unet_starts_the_unet_part_and_grows_normal_inputs(self):
        rgb_net = seeded(UNet(inputs=3), 2).eval()
        model = ContextUNet(UNet(inputs=6), FakeContext()).eval()
        load_init(model, rgb_net.state_dict())
        x = torch.randn(1, 6, 64, 64)
        with torch.no_grad():
            # The normals' weights are zero: the network is the RGB one.
            self.assertLess(float((model(x) - rgb_net(x[:, :3])).abs().max()), 1e-5)
        self.assertEqual(float(model.unet.enc[0][0].weight[:, 3:].abs().sum()), 0.0)

    def test_a_context_checkpoint_restores_the_whole_network(self):
        source = ContextUNet(seeded(UNet(inputs=6), 3), FakeContext())
        nn.init.normal_(source.inject[1].weight, 0, 0.1)
        target = ContextUNet(UNet(inputs=6), FakeContext())
        load_init(target, source.state_dict())
        for (k, a), b in zip(source.state_dict().items(), target.state_dict().values()):
            self.assertTrue(torch.equal(a, b), k)

    def test_mismatches_say_what_to_do(self):
        context_state = ContextUNet(UNet(inputs=3), FakeContext()).state_dict()
        with self.assertRaisesRegex(ValueError, "ctx.pt .*--context"):
            load_init(UNet(inputs=3), context_state, "ctx.pt")
        with self.assertRaisesRegex(ValueError, "other.pt is not a checkpoint"):
            load_init(UNet(inputs=3), {"weight": torch.zeros(1)}, "other.pt")


def write_dataset(folder, models, value, split="train", libraries=None):
    """A g2p_make_dataset-shaped folder: two 4x4 views per model, every pixel of an image equal to `value`; the
    library of model i is libraries[i] (default "Lib")."""
    from PIL import Image
    for sub in ("images", "labels", "normals"):
        os.makedirs(os.path.join(folder, sub))
    with open(os.path.join(folder, "manifest.csv"), "w", newline="") as f:
        out = csv.writer(f)
        out.writerow(["image", "library", "model", "split", "view", "labelled_pixels"] + CLASSES)
        for i, (model, view) in enumerate((m, v) for m in models for v in range(2)):
            name = f"{i:06d}.png"
            Image.fromarray(np.full((4, 4, 3), value, np.uint8)).save(os.path.join(folder, "images", name))
            Image.fromarray(np.full((4, 4), 1, np.uint8)).save(os.path.join(folder, "labels", name))
            Image.fromarray(np.full((4, 4, 3), 128, np.uint8)).save(os.path.join(folder, "normals", name))
            library = libraries[models.index(model)] if libraries else "Lib"
            out.writerow([name, library, model, split, view, 16] + [0, 16] + [0] * 10)


def write_run(folder, dataset, state, split_seed=1, tau=0.0, sha=None):
    """A train.py output folder: best.pt and the parts of training.json that ensemble.py and train.py --teacher
    read."""
    os.makedirs(folder)
    torch.save(state, os.path.join(folder, "best.pt"))
    if sha is None:
        _, sha = read_manifest(dataset)
    settings = {"dataset": dataset, "out": folder, "seed": split_seed + 10, "split_seed": split_seed,
                "val_share": 0.2, "val_library": "", "export_size": 32, "size": 16, "balance": 0.5,
                "normals": True, "context": ""}
    with open(os.path.join(folder, "training.json"), "w") as f:
        json.dump({"settings": settings, "exported": {"epoch": 1, "tau": tau, "val_miou": 0.5},
                   "manifest_sha256": sha}, f)


class TrainingRowsTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.models = [f"Lib/m{i}.obj" for i in range(10)]
        self.first, self.second = (os.path.join(self.tmp.name, d) for d in ("first", "second"))
        write_dataset(self.first, self.models, 10)
        write_dataset(self.second, self.models, 200)

    def tearDown(self):
        self.tmp.cleanup()

    def test_more_datasets_join_training_and_keep_validation_models_out(self):
        rows, val_rows, sha, more_sha = training_rows(self.first, [self.second], 0.2, 1)
        val_models = {r["model"] for r in val_rows}
        self.assertEqual(len(val_models), 2)
        self.assertEqual(len(val_rows), 4)
        self.assertTrue(all("root" not in r for r in val_rows))  # validation images come from DATASET only
        self.assertEqual(len(rows), 2 * 16)  # 8 training models, two views, both datasets
        self.assertFalse(val_models & {r["model"] for r in rows})
        self.assertEqual(sum(r.get("root") == self.second for r in rows), 16)
        self.assertEqual(len(sha), 64)
        self.assertEqual(len(more_sha), 1)
        # Without --more, the same validation models (the split depends on DATASET and the seed only).
        alone, alone_val, _, none = training_rows(self.first, [], 0.2, 1)
        self.assertEqual({r["model"] for r in alone_val}, val_models)
        self.assertEqual((len(alone), none), (16, []))

    def test_images_are_read_from_their_own_dataset(self):
        rows, _, _, _ = training_rows(self.first, [self.second], 0.2, 1)
        data = Dataset(self.first, rows, 4, False, normals=True)
        first = [float(data[i][0][0, 0, 0]) for i, r in enumerate(rows) if "root" not in r]
        second = [float(data[i][0][0, 0, 0]) for i, r in enumerate(rows) if "root" in r]
        normalised = [(v / 255 - MEAN[0]) / STD[0] for v in (10, 200)]
        self.assertTrue(all(abs(v - normalised[0]) < 1e-5 for v in first))
        self.assertTrue(all(abs(v - normalised[1]) < 1e-5 for v in second))
        self.assertEqual(tuple(data[0][0].shape), (6, 4, 4))

    def test_a_whole_library_can_be_the_validation_set(self):
        libraries = ["A"] * 6 + ["B"] * 4
        first, second = (os.path.join(self.tmp.name, d) for d in ("lib1", "lib2"))
        write_dataset(first, self.models, 10, libraries=libraries)
        write_dataset(second, self.models, 200, libraries=libraries)
        rows, val_rows, _, _ = training_rows(first, [second], 0.2, 1, "B")
        self.assertEqual({r["library"] for r in val_rows}, {"B"})
        self.assertEqual(len(val_rows), 8)  # every model of B, DATASET's images only
        self.assertEqual({r["library"] for r in rows}, {"A"})
        self.assertEqual(len(rows), 2 * 12)
        with self.assertRaisesRegex(ValueError, "--val-library C: not a training library of .* \\(it has A, B\\)"):
            training_rows(first, [], 0.2, 1, "C")
        single = os.path.join(self.tmp.name, "single")
        write_dataset(single, self.models, 10)
        with self.assertRaisesRegex(ValueError, "no other training library"):
            training_rows(single, [], 0.2, 1, "Lib")

    def test_a_dataset_of_other_models_is_refused(self):
        other = os.path.join(self.tmp.name, "other")
        write_dataset(other, self.models[:5] + ["Lib/stranger.obj"], 10)
        with self.assertRaisesRegex(ValueError, "--more .*other: 1 training models .*Lib/stranger.obj"):
            training_rows(self.first, [other], 0.2, 1)
        with self.assertRaisesRegex(ValueError, "missing.manifest.csv: not found"):
            training_rows(self.first, [os.path.join(self.tmp.name, "missing")], 0.2, 1)


class DatasetCase(unittest.TestCase):
    """A test case with a temporary folder (self.tmp) holding a 10-model dataset (self.dataset)."""

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dataset = os.path.join(self.tmp.name, "dataset")
        write_dataset(self.dataset, [f"Lib/m{i}.obj" for i in range(10)], 90)

    def tearDown(self):
        self.tmp.cleanup()

    def train_args(self, out, *args):
        return [self.dataset, out, "--size", "16", "--export-size", "32", "--val-share", "0.2", "--split-seed", "1",
                "--normals", "--threads", "1", *args]

    def run_train(self, out, *args):
        return subprocess.run([sys.executable, TRAIN, *self.train_args(out, *args)], capture_output=True, text=True)


class DistillationTest(DatasetCase):
    def test_the_loss_is_the_tempered_kl_on_object_pixels_only(self):
        # Two pixels, two classes: an object pixel without a class (254) and a background one (255), whose wild
        # logits must not count.
        student = torch.tensor([[[[0.0, 9.0]], [[0.0, -9.0]]]])
        teacher = torch.tensor([[[[2.0, 0.0]], [[0.0, 0.0]]]])
        label = torch.tensor([[[UNLABELLED_OBJECT, 255]]])
        t = [math.exp(1) / (math.exp(1) + 1), 1 / (math.exp(1) + 1)]  # softmax([2, 0] / T), T = 2
        expected = 4 * sum(p * math.log(p / 0.5) for p in t)  # T^2 KL(t || (0.5, 0.5))
        self.assertAlmostEqual(float(train.distillation_loss(student, teacher, label, 2.0)), expected, places=5)
        self.assertAlmostEqual(float(train.distillation_loss(teacher, teacher, label, 2.0)), 0.0, places=6)
        background = torch.full_like(label, 255)
        zero = train.distillation_loss(student.requires_grad_(), teacher, background, 2.0)
        self.assertEqual(float(zero), 0.0)
        zero.backward()  # no object pixel: still a loss the training loop can step on

    def test_object_pixels_without_a_class_are_kept_for_the_teacher(self):
        from PIL import Image
        name = "000000.png"  # model m0, view 0: its label and normals rewritten
        label = np.full((4, 4), 255, np.uint8)
        label[0, 0] = 3
        normals = np.full((4, 4, 3), 128, np.uint8)
        normals[0, :] = (128, 128, 255)  # row 0 is the object, facing the camera
        Image.fromarray(label).save(os.path.join(self.dataset, "labels", name))
        Image.fromarray(normals).save(os.path.join(self.dataset, "normals", name))
        rows, _ = read_manifest(self.dataset)
        plain = Dataset(self.dataset, rows[:1], 4, False)
        self.assertEqual(int((plain.label[0] == UNLABELLED_OBJECT).sum()), 0)
        data = Dataset(self.dataset, rows[:1], 4, False, objects=True)
        self.assertEqual(data.label[0, 0].tolist(), [3] + [UNLABELLED_OBJECT] * 3)
        self.assertTrue(bool((data.label[0, 1:] == 255).all()))
        self.assertIsNone(data.normal)  # the mask only: the network's inputs stay RGB
        # Crops centre on labelled pixels only: every crop of this image holds the class-3 pixel.
        for _ in range(20):
            _, crop, _ = augment(torch.zeros(3, 4, 4), data.label[0].long(), 4)
            self.assertIn(3, crop.tolist()[0] + crop.tolist()[-1])

    def test_the_teacher_is_the_runs_ensemble_before_their_logit_adjustment(self):
        a, b = (seeded(UNet(inputs=6), s).eval() for s in (1, 2))
        runs = [os.path.join(self.tmp.name, n) for n in ("a", "b")]
        write_run(runs[0], self.dataset, a.state_dict(), tau=0.5)
        write_run(runs[1], self.dataset, b.state_dict())
        _, sha = read_manifest(self.dataset)
        settings = {"split_seed": 1, "val_share": 0.2, "val_library": "", "normals": True}
        teacher = train.load_teacher(runs, "", sha, settings)
        x = torch.randn(1, 6, 32, 32)
        torch.testing.assert_close(teacher(x), Ensemble([a, b])(x), rtol=1e-4, atol=1e-5)
        self.assertFalse(any(p.requires_grad for p in teacher.parameters()))
        with self.assertRaisesRegex(ValueError, "--teacher .*a: validated on other models .*split_seed differs"):
            train.load_teacher(runs, "", sha, dict(settings, split_seed=2))
        with self.assertRaisesRegex(ValueError, "--teacher .*a: validated on other models .*manifest differs"):
            train.load_teacher(runs, "", "0" * 64, settings)
        with self.assertRaisesRegex(ValueError, "--teacher .*a: takes 6 input channels, this run 3"):
            train.load_teacher(runs, "", sha, dict(settings, normals=False))

    def test_a_run_with_a_teacher_moves_towards_it(self):
        teacher_run = os.path.join(self.tmp.name, "teacher")
        teacher = seeded(UNet(inputs=6), 5).eval()
        write_run(teacher_run, self.dataset, teacher.state_dict())
        start = os.path.join(self.tmp.name, "start.pt")
        torch.save(seeded(UNet(inputs=6), 6).state_dict(), start)
        out = os.path.join(self.tmp.name, "out")
        done = self.run_train(out, "--teacher", teacher_run, "--distill-weight", "1", "--init", start,
                              "--epochs", "4", "--batch", "2", "--lr", "3e-3", "--seed", "3")
        self.assertEqual(done.returncode, 0, done.stderr)
        with open(os.path.join(out, "training.json")) as f:
            record = json.load(f)
        self.assertEqual(record["settings"]["teacher"], [teacher_run])
        x = Dataset(self.dataset, read_manifest(self.dataset)[0][:4], 16, False, normals=True)
        x = F.interpolate(torch.stack([x[i][0] for i in range(4)]), size=(32, 32))
        label = torch.zeros(4, 32, 32, dtype=torch.long)  # every pixel counts

        def kl(state_path):
            student = UNet(inputs=6)
            student.load_state_dict(torch.load(state_path))
            with torch.no_grad():
                return float(train.distillation_loss(student.eval()(x), teacher(x), label, 2.0))

        before, after = kl(start), kl(os.path.join(out, "checkpoint.pt"))
        self.assertLess(after, 0.5 * before)

    def test_a_teacher_with_no_weight_leaves_the_run_as_it_was(self):
        # The same initial weights, batches and augmentations as without a teacher: runs compare pair-wise.
        teacher_run = os.path.join(self.tmp.name, "teacher")
        write_run(teacher_run, self.dataset, seeded(UNet(inputs=6), 5).state_dict())
        outs = [os.path.join(self.tmp.name, n) for n in ("plain", "taught")]
        common = ("--epochs", "2", "--batch", "4", "--seed", "4")
        for out, extra in zip(outs, ([], ["--teacher", teacher_run, "--distill-weight", "0"])):
            done = self.run_train(out, *common, *extra)
            self.assertEqual(done.returncode, 0, done.stderr)
        plain, taught = (torch.load(os.path.join(out, "checkpoint.pt")) for out in outs)
        for key in plain:
            torch.testing.assert_close(taught[key], plain[key], rtol=0, atol=0, msg=key)

    def test_teachers_and_datasets_that_cannot_serve_are_refused(self):
        other = os.path.join(self.tmp.name, "other")
        write_run(other, self.dataset, seeded(UNet(inputs=6), 1).state_dict(), split_seed=2)
        done = self.run_train(os.path.join(self.tmp.name, "out"), "--teacher", other, "--epochs", "1")
        self.assertEqual(done.returncode, 2)
        self.assertRegex(done.stderr, "--teacher .*other: validated on other models than this run "
                                      r"\(split_seed differs\)")
        done = self.run_train(os.path.join(self.tmp.name, "out"), "--teacher", os.path.join(self.tmp.name, "none"))
        self.assertRegex(done.stderr, r"none.training.json: not found")
        import shutil
        shutil.rmtree(os.path.join(self.dataset, "normals"))
        done = self.run_train(os.path.join(self.tmp.name, "out2"), "--teacher", other)
        self.assertRegex(done.stderr, "--teacher needs .*normals for the object mask")
        done = self.run_train(os.path.join(self.tmp.name, "out3"), "--teacher", other, "--distill-weight", "2")
        self.assertRegex(done.stderr, "--distill-weight must lie in 0..1")
        done = self.run_train(os.path.join(self.tmp.name, "out4"), "--distill-temperature", "3")
        self.assertRegex(done.stderr, "--distill-weight and --distill-temperature need --teacher")

    def test_context_settings_that_cannot_work_are_refused(self):
        out = os.path.join(self.tmp.name, "out")
        done = self.run_train(out, "--extra-context", "mobilenet_v2=" + self.tmp.name)
        self.assertEqual(done.returncode, 2)
        self.assertRegex(done.stderr, "--extra-context need --context")
        done = self.run_train(out, "--context", self.tmp.name, "--extra-context", "resnet=" + self.tmp.name)
        self.assertRegex(done.stderr, "--extra-context resnet=.*: expected KIND=DIR with KIND one of mobilenet_v2, nanodet")
        done = self.run_train(out, "--context", self.tmp.name, "--context-kind", "mobilenet_v2")
        self.assertEqual(done.returncode, 2)
        self.assertRegex(done.stderr, "no mobilenet_v2.json .the mobilenet_v2 encoder")
        self.assertFalse(os.path.exists(os.path.join(out, "g2p-materials.onnx")))


def snapshot(folder):
    """{file name: SHA-256 of its bytes} of a folder's files (digests keep a failed comparison's diff short)."""
    out = {}
    for name in sorted(os.listdir(folder)):
        path = os.path.join(folder, name)
        if os.path.isfile(path):
            with open(path, "rb") as f:
                out[name] = hashlib.sha256(f.read()).hexdigest()
    return out


class ExportTest(DatasetCase):
    """What OUT holds is never lost half-way: a run is not overwritten unless asked, and a failed export leaves
    OUT's exported model as it was."""

    def test_a_staged_export_replaces_only_when_it_completes(self):
        out = os.path.join(self.tmp.name, "out")
        os.makedirs(out)
        for name, text in (("a.txt", "old a"), ("b.txt", "old b")):
            with open(os.path.join(out, name), "w") as f:
                f.write(text)
        with self.assertRaisesRegex(RuntimeError, "half-way"):
            with staged_export(out) as stage:
                with open(os.path.join(stage, "a.txt"), "w") as f:
                    f.write("new a")
                raise RuntimeError("failed half-way")
        digest = {text: hashlib.sha256(text.encode()).hexdigest() for text in ("old a", "old b", "new a")}
        self.assertEqual(snapshot(out), {"a.txt": digest["old a"], "b.txt": digest["old b"]})
        self.assertEqual(sorted(os.listdir(out)), ["a.txt", "b.txt"])  # the scratch folder is gone
        with staged_export(out) as stage:
            with open(os.path.join(stage, "a.txt"), "w") as f:
                f.write("new a")
        self.assertEqual(snapshot(out), {"a.txt": digest["new a"], "b.txt": digest["old b"]})
        self.assertEqual(sorted(os.listdir(out)), ["a.txt", "b.txt"])

    def test_an_out_holding_a_run_is_refused_unless_overwrite_is_given(self):
        out = os.path.join(self.tmp.name, "out")
        done = self.run_train(out, "--epochs", "1", "--batch", "8")
        self.assertEqual(done.returncode, 0, done.stderr)
        first = snapshot(out)
        self.assertEqual(set(first), set(RUN_FILES))
        done = self.run_train(out, "--epochs", "1", "--batch", "8", "--seed", "2")
        self.assertEqual(done.returncode, 2)
        self.assertRegex(done.stderr, r"out: already holds a run \(g2p-materials.onnx, .*best.pt\); .*--overwrite")
        self.assertEqual(snapshot(out), first)
        done = self.run_train(out, "--epochs", "1", "--batch", "8", "--seed", "2", "--overwrite")
        self.assertEqual(done.returncode, 0, done.stderr)
        second = snapshot(out)
        self.assertEqual(set(second), set(RUN_FILES))
        self.assertNotEqual(second["checkpoint.pt"], first["checkpoint.pt"])
        self.assertNotEqual(second["training.json"], first["training.json"])

    def test_a_failed_export_leaves_the_exported_model_it_would_replace(self):
        out = os.path.join(self.tmp.name, "out")
        done = self.run_train(out, "--epochs", "1", "--batch", "8")
        self.assertEqual(done.returncode, 0, done.stderr)
        first = snapshot(out)

        def failing_card(*args):
            raise OSError("disk full")

        argv, card = sys.argv, train.write_model_card
        sys.argv = [TRAIN, *self.train_args(out, "--epochs", "1", "--batch", "8", "--seed", "2", "--overwrite")]
        train.write_model_card = failing_card
        try:
            with self.assertRaisesRegex(OSError, "disk full"):
                train.main()
        finally:
            sys.argv, train.write_model_card = argv, card
        now = snapshot(out)
        self.assertEqual(sorted(os.listdir(out)), sorted(RUN_FILES))  # no scratch folder left
        for name in ("g2p-materials.onnx", "g2p-materials.json", "training.json"):
            self.assertEqual(now[name], first[name], name)
        self.assertNotEqual(now["checkpoint.pt"], first["checkpoint.pt"])  # --overwrite: checkpoints are replaced


class ShippedManifestTest(unittest.TestCase):
    """libg2p/data/models/manifest.csv.gz is the exact data manifest the shipped network was trained on: its
    SHA-256 is the one training.json records for the run (or, for an ensemble, each member's run), and the split
    train.py makes of it with the recorded settings gives the recorded numbers of training and validation images."""

    def test_the_committed_manifest_is_the_one_the_network_was_trained_on(self):
        models = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "libg2p", "data", "models")
        with open(os.path.join(models, "training.json")) as f:
            record = json.load(f)
        runs = record["members"] if "ensemble" in record else [record]
        self.assertTrue(runs)
        with gzip.open(os.path.join(models, "manifest.csv.gz"), "rb") as f:
            manifest = f.read()
        if "ensemble" in record:
            self.assertEqual(hashlib.sha256(manifest).hexdigest(), record["ensemble"]["manifest_sha256"])
        for run in runs:
            self.assertEqual(hashlib.sha256(manifest).hexdigest(), run["manifest_sha256"])
            settings = run["settings"]
            with tempfile.TemporaryDirectory() as dataset:
                with open(os.path.join(dataset, "manifest.csv"), "wb") as f:
                    f.write(manifest)
                rows, val_rows, sha, _ = training_rows(dataset, [], settings["val_share"],
                                                       settings.get("split_seed", settings["seed"]),
                                                       settings.get("val_library", ""))
            self.assertEqual(sha, run["manifest_sha256"])
            self.assertEqual(len(rows), run["images"])
            self.assertEqual(len(validation_subsample(val_rows)), run["validation_images"])
            self.assertFalse({r["model"] for r in rows} & {r["model"] for r in val_rows})
            self.assertEqual({r["split"] for r in rows}, {"train"})


if __name__ == "__main__":
    unittest.main()
