#!/usr/bin/python3
"""tools/training is a package whose imports go one way: every module is placed in LAYERS (its __init__.py), imports
only modules placed before it (so the import graph has no cycle), and names them as a package does; every step with a
main() runs the same as a script and with python3 -m. The imports are read with ast, so no torch is needed; a step is
run only where the packages it imports are installed."""
import ast
import importlib.util
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
PACKAGE = os.path.join(ROOT, "tools", "training")


def modules():
    """{module name: its parsed source} of every Python file of the package but __init__.py."""
    out = {}
    for name in sorted(os.listdir(PACKAGE)):
        if name.endswith(".py") and name != "__init__.py":
            with open(os.path.join(PACKAGE, name)) as f:
                out[name[:-3]] = ast.parse(f.read(), name)
    return out


def layers():
    with open(os.path.join(PACKAGE, "__init__.py")) as f:
        tree = ast.parse(f.read())
    for node in tree.body:
        if isinstance(node, ast.Assign) and [t.id for t in node.targets] == ["LAYERS"]:
            return list(ast.literal_eval(node.value))
    raise AssertionError("tools/training/__init__.py defines no LAYERS")


def imports(tree, siblings):
    """(the package's modules `tree` imports, anywhere in it, as (name, line) pairs; its imports of a sibling by its
    bare name, which work only with tools/training itself on sys.path)."""
    inside, bare = [], []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.level == 1:
            names = [node.module] if node.module else [a.name for a in node.names]
            inside += [(n.split(".")[0], node.lineno) for n in names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            if node.module == "tools.training":
                inside += [(a.name, node.lineno) for a in node.names]
            elif node.module.startswith("tools.training."):
                inside.append((node.module.split(".")[2], node.lineno))
            elif node.module.split(".")[0] in siblings:
                bare.append((node.module, node.lineno))
        elif isinstance(node, ast.Import):
            for a in node.names:
                if a.name.startswith("tools.training."):
                    inside.append((a.name.split(".")[2], node.lineno))
                elif a.name.split(".")[0] in siblings:
                    bare.append((a.name, node.lineno))
    return inside, bare


class ImportOrderTest(unittest.TestCase):
    def test_every_module_has_a_place_in_the_layers(self):
        order = layers()
        self.assertEqual(len(order), len(set(order)), "a module is listed twice in LAYERS")
        self.assertEqual(sorted(order), sorted(modules()), "LAYERS must list every module of tools/training")

    def test_modules_import_only_modules_below_them(self):
        order = layers()
        rank = {name: i for i, name in enumerate(order)}
        found = modules()
        for name, tree in found.items():
            inside, bare = imports(tree, set(found))
            self.assertEqual(bare, [], f"{name}.py imports a sibling by its bare name: use a relative import")
            for target, line in inside:
                self.assertIn(target, rank, f"{name}.py:{line} imports tools.training.{target}, which does not exist")
                self.assertLess(rank[target], rank[name], f"{name}.py:{line} imports {target}, which LAYERS places "
                                                          f"above it: imports go one way ({' < '.join(order)})")

    def test_the_import_graph_has_no_cycle(self):
        found = modules()
        graph = {}
        for name, tree in found.items():
            inside, bare = imports(tree, set(found))  # a bare import joins a cycle as surely as a relative one
            graph[name] = sorted({t for t, _ in inside} | {t.split(".")[0] for t, _ in bare})
        state = {}  # name -> "open" while its imports are being followed, "done" after

        def visit(name, path):
            if state.get(name) == "open":
                self.fail("import cycle: " + " -> ".join(path[path.index(name):] + [name]))
            if state.get(name) == "done":
                return
            state[name] = "open"
            for target in graph.get(name, []):
                visit(target, path + [name])
            state[name] = "done"

        for name in graph:
            visit(name, [])

    def test_a_step_run_as_a_script_imports_the_package(self):
        # A module with relative imports and a main() must set itself up as python3 -m would when run as a script.
        for name, tree in modules().items():
            relative = any(isinstance(n, ast.ImportFrom) and n.level for n in ast.walk(tree))
            steps = any(isinstance(n, ast.FunctionDef) and n.name == "main" for n in tree.body)
            if relative and steps:
                sets = [n for n in ast.walk(tree) if isinstance(n, ast.Assign)
                        and any(isinstance(t, ast.Name) and t.id == "__package__" for t in n.targets)]
                self.assertTrue(sets, f"{name}.py runs as a script but never sets __package__")


def runnable(tree):
    """Whether every package the module imports at its top level is installed here."""
    for node in tree.body:
        names = []
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names = [node.module]
        for name in names:
            if importlib.util.find_spec(name.split(".")[0]) is None:
                return False
    return True


class EntryPointTest(unittest.TestCase):
    def test_every_step_runs_the_same_as_a_script_and_as_a_module(self):
        ran = []
        for name, tree in modules().items():
            if not any(isinstance(n, ast.FunctionDef) and n.name == "main" for n in tree.body) or not runnable(tree):
                continue
            script = subprocess.run([sys.executable, os.path.join(PACKAGE, name + ".py"), "--help"],
                                    capture_output=True, text=True, timeout=120, cwd=tempfile.gettempdir())
            module = subprocess.run([sys.executable, "-m", "tools.training." + name, "--help"],
                                    capture_output=True, text=True, timeout=120, cwd=ROOT)
            self.assertNotIn("Traceback", script.stderr, name)
            self.assertEqual((module.returncode, module.stdout, module.stderr),
                             (script.returncode, script.stdout, script.stderr), name)
            ran.append(name)
        self.assertIn("attribution", ran)  # needs nothing beyond Python itself


if __name__ == "__main__":
    unittest.main()
