"""g2p.batch from Python: rows as dicts (and a DataFrame with pandas), the same
worker-process isolation as `g2p batch` (a crashing model does not take the
interpreter down), resume, progress, and errors as g2p exceptions. ctest sets
PYTHONPATH to the built module; the module finds the g2p executable of its
build."""

import os
import pathlib
import shutil
import stat
import tempfile
import unittest

import g2p

ROOT = pathlib.Path(__file__).resolve().parents[2]
HAMMER = pathlib.Path(os.environ.get("G2P_HAMMER_OBJ", str(ROOT / "examples" / "data" / "hammer.obj")))
QUICK = g2p.PipelineOptions(views=g2p.ViewOptions(num_views=6, width=160, height=160))

try:
    import pandas
except ImportError:
    pandas = None


def hammer_copy(folder, name):
    folder = pathlib.Path(folder)
    shutil.copy(HAMMER, folder / f"{name}.obj")
    shutil.copy(HAMMER.with_suffix(".mtl"), folder / f"{name}.mtl")
    return folder / f"{name}.obj"


def crashing_tool(folder, real_tool):
    """A g2p stand-in that dies by SIGSEGV on models named *crash*, as a crash in a library would."""
    path = pathlib.Path(folder) / "g2p-wrapper.sh"
    path.write_text('#!/bin/sh\ncase "$2" in *crash*) kill -SEGV $$ ;; esac\nexec "%s" "$@"\n' % real_tool)
    path.chmod(path.stat().st_mode | stat.S_IEXEC)
    return str(path)


class BatchTest(unittest.TestCase):
    def setUp(self):
        self._tmp = tempfile.TemporaryDirectory(prefix="g2p-batch-")
        self.dir = pathlib.Path(self._tmp.name)

    def tearDown(self):
        self._tmp.cleanup()

    def test_rows_resume_and_progress(self):
        good = hammer_copy(self.dir, "good")
        empty = self.dir / "empty.obj"
        empty.write_bytes(b"")
        seen = []
        rows = g2p.batch([good, str(empty)], self.dir / "out", jobs=2, options=QUICK, progress=seen.append)
        self.assertEqual([r["name"] for r in rows], ["good", "empty"])
        ok, bad = rows
        self.assertEqual(ok["status"], "ok", ok["error"])
        self.assertEqual(ok["parts"], 2)
        self.assertEqual(ok["materials"], ["Wood", "Metal"])
        self.assertAlmostEqual(ok["mass_kg"], 1.418, delta=0.05)
        self.assertLess(ok["mass_min_kg"], ok["mass_kg"])
        self.assertIn("render", ok["stage_seconds"])
        self.assertGreater(ok["peak_rss_mib"], 10)
        self.assertTrue((pathlib.Path(ok["output"]) / "run.json").is_file())
        self.assertEqual(bad["status"], "failed")
        self.assertEqual(bad["error"], f"parse error: {empty}: the file is empty")
        self.assertEqual(seen[-1]["done"], 2)
        self.assertEqual(seen[-1]["failed"], 1)

        # Unchanged: a rerun starts nothing and returns the same rows.
        seen.clear()
        again = g2p.batch([good, empty], self.dir / "out", options=QUICK, progress=seen.append)
        self.assertEqual([r["key"] for r in again], [r["key"] for r in rows])
        self.assertEqual(seen[-1]["skipped"], 2)
        self.assertEqual(g2p.read_batch_index(self.dir / "out"), again)

    @unittest.skipIf(not os.environ.get("G2P_TEST_TOOL"), "G2P_TEST_TOOL (the built g2p) is not set")
    def test_a_crashing_model_is_a_row_not_a_dead_interpreter(self):
        tool = crashing_tool(self.dir, os.environ["G2P_TEST_TOOL"])
        models = [hammer_copy(self.dir, "fine"), hammer_copy(self.dir, "crash")]
        rows = g2p.batch(models, self.dir / "out", options=QUICK, tool=tool)
        by_name = {r["name"]: r for r in rows}
        self.assertEqual(by_name["fine"]["status"], "ok")
        self.assertEqual(by_name["crash"]["status"], "failed")
        self.assertEqual(by_name["crash"]["error"], "crashed (SIGSEGV)")
        self.assertEqual(by_name["crash"]["exit_code"], 128 + 11)

    @unittest.skipIf(pandas is None, "pandas (python3-pandas) is not installed")
    def test_a_dataframe_with_pandas(self):
        frame = g2p.batch(hammer_copy(self.dir, "h"), self.dir / "out", options=QUICK, dataframe=True)
        self.assertIsInstance(frame, pandas.DataFrame)
        self.assertEqual(list(frame["status"]), ["ok"])
        self.assertEqual(int(frame.loc[0, "parts"]), 2)
        self.assertEqual(list(g2p.batch_dataframe(g2p.read_batch_index(self.dir / "out"))["name"]), ["h"])

    def test_options_reach_each_run_as_an_options_file(self):
        # A JSON Lines row's own options over the batch's; the run's folder keeps what it ran with.
        good = hammer_copy(self.dir, "h")
        manifest = self.dir / "assets.jsonl"
        manifest.write_text('{"path": "h.obj", "options": {"formats": ["urdf"], "views": {"count": 4}}}\n')
        options = g2p.PipelineOptions(views=g2p.ViewOptions(num_views=6, width=160, height=160), formats=["mjcf"])
        rows = g2p.batch(None, self.dir / "out", manifest=manifest, options=options)
        self.assertEqual(rows[0]["status"], "ok", rows[0]["error"])
        used, _ = g2p.read_options_file(self.dir / "out" / "h" / "options.json")
        self.assertEqual(used.views.num_views, 4)
        self.assertEqual(used.views.width, 160)
        self.assertEqual(used.formats, ["urdf"])
        self.assertTrue((self.dir / "out" / "h" / "h.urdf").exists())
        # The text round-trips, and a bad key is named.
        again, _ = g2p.parse_options_file(g2p.options_file_json(used))
        self.assertEqual(again.views.num_views, 4)
        with self.assertRaises(g2p.ParseError) as caught:
            g2p.parse_options_file('{"views": {"count": "six"}}')
        self.assertIn("views.count: expected an integer", str(caught.exception))

    def test_errors_are_g2p_exceptions(self):
        manifest = self.dir / "assets.csv"
        manifest.write_text("path,height\nx.obj,0.3\ny.obj,tall\n")
        with self.assertRaises(g2p.ParseError) as caught:
            g2p.batch(None, self.dir / "out", manifest=manifest)
        self.assertIn(f"{manifest}:3: height 'tall'", str(caught.exception))
        with self.assertRaises(g2p.NotFoundError):
            g2p.batch([HAMMER], self.dir / "out", tool=str(self.dir / "no-such-g2p"))
        with self.assertRaises(g2p.NotFoundError):
            g2p.batch([str(self.dir / "*.fbx")], self.dir / "out")
        with self.assertRaises(TypeError):
            g2p.batch([HAMMER], self.dir / "out", progress=42)


if __name__ == "__main__":
    unittest.main()
