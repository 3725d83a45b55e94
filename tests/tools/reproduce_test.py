#!/usr/bin/python3
"""tools/training/reproduce.sh's command line: usage, refused options and a missing build, each with a message that
names the problem, before anything is unpacked, downloaded or trained (its training steps are measured in
docs/training.md, not here: they take an hour and a half)."""
import os
import subprocess
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools", "training", "reproduce.sh")


def reproduce(*args, env=None):
    return subprocess.run(["bash", SCRIPT, *args], capture_output=True, text=True, timeout=60,
                          env={**os.environ, **(env or {})})


class ReproduceCommandLineTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.work = os.path.join(self.tmp.name, "work")

    def tearDown(self):
        self.tmp.cleanup()

    def test_usage_names_every_option(self):
        done = reproduce()
        self.assertEqual(done.returncode, 2)
        for option in ("WORK", "--data-only", "--ensemble", "--epochs N", "--continuations C", "--continue-epochs K", "--seeds S",
                       "--max-minutes M"):
            self.assertIn(option, done.stderr)

    def test_unknown_and_incomplete_options_are_refused_before_any_work(self):
        done = reproduce(self.work, "--continue", "2")
        self.assertEqual(done.returncode, 2)
        self.assertIn("unknown option --continue", done.stderr)
        done = reproduce(self.work, "--continue-epochs")
        self.assertNotEqual(done.returncode, 0)
        self.assertIn("--continue-epochs needs a number", done.stderr)
        done = reproduce(self.work, "--continuations", "3")
        self.assertEqual(done.returncode, 2)
        self.assertIn("--continuations takes 0, 1 or 2, not 3", done.stderr)
        done = reproduce(self.work, "--seeds", "3")
        self.assertEqual(done.returncode, 2)
        self.assertIn("--seeds takes 1 or 2, not 3", done.stderr)
        done = reproduce(self.work, "--seeds", "2", "--continuations", "0")  # nothing for the seeds to differ in
        self.assertEqual(done.returncode, 2)
        self.assertIn("--seeds 2 needs a continuation", done.stderr)
        self.assertFalse(os.path.exists(self.work))  # nothing created

    def test_a_missing_build_is_named(self):
        empty = os.path.join(self.tmp.name, "bin")
        os.mkdir(empty)
        done = reproduce(self.work, "--continue-epochs", "0", env={"G2P_BIN": empty})
        self.assertEqual(done.returncode, 1)
        self.assertIn(f"{empty}/g2p not found; build libg2p first or set G2P_BIN", done.stderr)
        self.assertFalse(os.path.exists(self.work))


if __name__ == "__main__":
    unittest.main()
