"""g2p.batch on a Dask cluster (client=...) and `g2p batch --scheduler`: a
LocalCluster of 2 worker processes on loopback runs the same isolated
per-model work as the local pool: a crash and a hang among good models are
rows, a rerun skips, a stop cancels what runs. Skipped without
python3-distributed."""

import json
import os
import pathlib
import shutil
import stat
import subprocess
import tempfile
import time
import unittest

import g2p

try:
    from distributed import Client, LocalCluster, get_task_stream
except ImportError:
    Client = LocalCluster = get_task_stream = None

ROOT = pathlib.Path(__file__).resolve().parents[2]
HAMMER = pathlib.Path(os.environ.get("G2P_HAMMER_OBJ", str(ROOT / "examples" / "data" / "hammer.obj")))
TOOL = os.environ.get("G2P_TEST_TOOL", "")
QUICK = g2p.PipelineOptions(views=g2p.ViewOptions(num_views=6, width=160, height=160))


def hammer_copy(folder, name):
    folder = pathlib.Path(folder)
    shutil.copy(HAMMER, folder / f"{name}.obj")
    shutil.copy(HAMMER.with_suffix(".mtl"), folder / f"{name}.mtl")
    return folder / f"{name}.obj"


def misbehaving_tool(folder):
    """g2p, except that a model named *crash* dies by SIGSEGV and one named *hang* never ends."""
    path = pathlib.Path(folder) / "g2p-wrapper.sh"
    path.write_text(
        '#!/bin/sh\ncase "$2" in *crash*) kill -SEGV $$ ;; *hang*) exec sleep 300 ;; esac\nexec "%s" "$@"\n' % TOOL
    )
    path.chmod(path.stat().st_mode | stat.S_IEXEC)
    return str(path)


@unittest.skipIf(LocalCluster is None, "python3-distributed is not installed")
@unittest.skipIf(not TOOL, "G2P_TEST_TOOL (the built g2p) is not set")
class DaskBatchTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.cluster = LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None
        )
        cls.client = Client(cls.cluster)

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        cls.cluster.close()

    def setUp(self):
        self._tmp = tempfile.TemporaryDirectory(prefix="g2p-dask-")
        self.dir = pathlib.Path(self._tmp.name)

    def tearDown(self):
        self._tmp.cleanup()

    def test_a_crash_and_a_hang_among_good_models_and_a_rerun(self):
        models = [hammer_copy(self.dir, n) for n in ("good1", "crash", "hang", "good2")]
        empty = self.dir / "empty.obj"
        empty.write_bytes(b"")
        models.append(empty)
        out = self.dir / "out"
        with get_task_stream(self.client) as tasks:
            rows = g2p.batch(models, out, options=QUICK, timeout=15, tool=misbehaving_tool(self.dir),
                             client=self.client)
        # Every model was a task of the cluster, on both of its workers.
        ran = [t for t in tasks.data if t["key"].startswith("g2p-")]
        self.assertEqual(len(ran), 5, tasks.data)
        self.assertEqual(len({t["worker"] for t in ran}), 2, ran)
        by_name = {r["name"]: r for r in rows}
        self.assertEqual([r["name"] for r in rows], ["good1", "crash", "hang", "good2", "empty"])
        for good in ("good1", "good2"):
            self.assertEqual(by_name[good]["status"], "ok", by_name[good]["error"])
            self.assertEqual(by_name[good]["parts"], 2)
            self.assertTrue((out / good / "run.json").is_file())
        self.assertEqual(by_name["crash"]["error"], "crashed (SIGSEGV)")
        self.assertEqual(by_name["hang"]["error"], "timed out after 15 s")
        self.assertEqual(by_name["empty"]["error"], f"parse error: {empty}: the file is empty")
        self.assertEqual(g2p.read_batch_index(out), rows)
        self.assertEqual(sorted(p.name for p in out.iterdir() if p.name.startswith(".")), [".g2p-batch.lock"])

        # The same index the local pool keeps: a rerun (local or on the cluster) starts nothing.
        seen = []
        again = g2p.batch(models, out, options=QUICK, timeout=15, tool=misbehaving_tool(self.dir), client=self.client,
                          progress=seen.append)
        self.assertEqual(seen[-1]["skipped"], 5)
        self.assertEqual([r["key"] for r in again], [r["key"] for r in rows])

    def test_a_stop_cancels_the_running_tasks_and_keeps_the_finished(self):
        models = [hammer_copy(self.dir, "quick"), hammer_copy(self.dir, "hang")]
        out = self.dir / "out"

        def progress(p):
            if p["last"].startswith("quick: ok"):
                raise RuntimeError("stop here")

        start = time.monotonic()
        with self.assertRaisesRegex(RuntimeError, "stop here"):
            g2p.batch(models, out, options=QUICK, tool=misbehaving_tool(self.dir), client=self.client,
                      progress=progress)
        self.assertLess(time.monotonic() - start, 60)  # not the hanging task's 300 s
        index = {r["name"]: r for r in g2p.read_batch_index(out)}
        self.assertEqual(index["quick"]["status"], "ok")
        self.assertEqual(index["hang"]["status"], "cancelled")
        self.assertFalse((out / "hang").exists())

    def test_the_command_line_runs_on_the_scheduler(self):
        model = hammer_copy(self.dir, "cli")
        out = self.dir / "out"
        env = dict(os.environ)
        r = subprocess.run(
            [TOOL, "batch", str(model), "-o", str(out), "--views", "6", "--resolution", "160", "--format", "urdf",
             "--scheduler", self.cluster.scheduler_address],
            capture_output=True, text=True, env=env, timeout=240,
        )
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertIn("1 assets: 1 ok, 0 failed on the Dask cluster", r.stdout)
        index = json.loads((out / "index.json").read_text())["assets"]
        self.assertEqual(index[0]["status"], "ok")
        # The flags reached the worker's run as its options file.
        self.assertTrue((out / "cli" / "cli.urdf").exists())
        self.assertFalse((out / "cli" / "cli.xml").exists())
        self.assertEqual(json.loads((out / "cli" / "options.json").read_text())["views"]["count"], 6)
        # An address where no scheduler listens: a clear error, exit 1.
        r = subprocess.run(
            [TOOL, "batch", str(model), "-o", str(self.dir / "none"), "--scheduler", "tcp://me:secret@127.0.0.1:9"],
            capture_output=True, text=True, env=env, timeout=240,
        )
        self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
        self.assertIn("cannot reach the Dask scheduler at tcp://***@127.0.0.1:9", r.stderr)
        self.assertNotIn("secret", r.stderr + r.stdout)


if __name__ == "__main__":
    unittest.main()
