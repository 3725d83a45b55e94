#!/usr/bin/env python3
"""Checks libg2p/data/objects.json: it is up to date with scripts/objects/kinds.json and WordNet
(build_objects.py --check), and it has the properties g2p relies on.

Run directly or from ctest.  If the WordNet database (Debian package wordnet-base) is absent, the
--check step cannot run: the test prints "SKIPPED: ..." and exits 0 without checking anything else.
"""

import json
import os
import subprocess
import sys
import unittest

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
SCRIPT = os.path.join(ROOT, "scripts", "objects", "build_objects.py")
TABLE = os.path.join(ROOT, "libg2p", "data", "objects.json")
SCHEMA = os.path.join(ROOT, "libg2p", "data", "objects.schema.json")
WORDNET = "/usr/share/wordnet"

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(SCRIPT))
import build_objects  # noqa: E402  (for its COCO, CLASSES and GROUPS lists and validator)


def load():
    with open(TABLE, encoding="utf-8") as f:
        return json.load(f)


class ObjectsTable(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.table = load()
        cls.kinds = cls.table["kinds"]
        cls.by_name = {k["name"]: k for k in cls.kinds}
        cls.owner = {}
        for k in cls.kinds:
            for t in k["terms"]:
                cls.owner.setdefault(t, []).append(k["name"])

    def test_up_to_date(self):
        r = subprocess.run([sys.executable, SCRIPT, "--check"], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)

    def test_header(self):
        self.assertEqual(self.table["format"], "g2p-object-table")
        self.assertEqual(self.table["version"], 1)
        self.assertTrue(self.table["wordnet"].startswith("WordNet 3.0 (Debian wordnet-base "))

    def test_validator_accepts_table(self):
        self.assertEqual(build_objects.validate_table(self.table), [])

    def test_validator_rejects_bad_entries(self):
        k = json.loads(json.dumps(self.by_name["chair"]))
        k["mass_kg"] = [5, 4]
        k["typical"]["height_m"] = 9.0
        k["materials"] = [{"role": "frame", "class": "Unobtainium"}]
        errors = []
        build_objects.validate_kind(k, errors)
        self.assertTrue(any("lo must be <= hi" in e for e in errors), errors)
        self.assertTrue(any("typical height" in e for e in errors), errors)
        self.assertTrue(any("bad material" in e for e in errors), errors)

    def test_size_of_table(self):
        self.assertGreaterEqual(len(self.kinds), 150)
        self.assertEqual(len(self.by_name), len(self.kinds), "kind names must be unique")
        synsets = [s for k in self.kinds for s in k["synsets"]]
        self.assertEqual(len(synsets), len(set(synsets)), "a synset may belong to one kind only")

    def test_coco_classes_each_mapped_once(self):
        cocos = [k["coco"] for k in self.kinds if "coco" in k]
        self.assertEqual(len(build_objects.COCO), 80)
        self.assertEqual(sorted(cocos), sorted(build_objects.COCO))

    def test_ranges_and_typical_sizes(self):
        for k in self.kinds:
            with self.subTest(kind=k["name"]):
                for f in ("height_m", "longest_side_m", "mass_kg"):
                    lo, hi = k[f]
                    self.assertGreater(lo, 0)
                    self.assertLessEqual(lo, hi)
                lo, hi = k["mass_kg"]
                self.assertLess(lo, hi)
                self.assertGreaterEqual(hi / lo, 1.5 - 1e-9)
                t = k["typical"]
                self.assertTrue(k["height_m"][0] <= t["height_m"] <= k["height_m"][1])
                self.assertTrue(k["longest_side_m"][0] <= t["longest_side_m"] <= k["longest_side_m"][1])
                self.assertLessEqual(t["height_m"], t["longest_side_m"])

    def test_classes_structure_hidden(self):
        for k in self.kinds:
            with self.subTest(kind=k["name"]):
                self.assertIn(k["group"], build_objects.GROUPS)
                self.assertIn(k["structure"], ("solid", "hollow", "shell_with_contents"))
                self.assertTrue(1 <= len(k["materials"]) <= 5)
                for m in k["materials"]:
                    self.assertIn(m["class"], build_objects.CLASSES)
                total = 0.0
                for h in k["hidden"]:
                    self.assertTrue(0 < h["mass_fraction"] <= 0.9)
                    self.assertIn(h["where"], ("bottom", "centre", "spread"))
                    total += h["mass_fraction"]
                self.assertLessEqual(total, 0.9 + 1e-9)
                for key in ("size", "mass", "materials", "hidden"):
                    self.assertTrue(k["sources"][key].strip())

    def test_terms(self):
        for k in self.kinds:
            with self.subTest(kind=k["name"]):
                self.assertEqual(k["terms"], sorted(set(k["terms"])))
                self.assertTrue(all(len(t) >= 3 and t == t.lower() for t in k["terms"]))
                if len(k["name"]) >= 3:
                    self.assertIn(k["name"], k["terms"])
        dup = {t: o for t, o in self.owner.items() if len(o) > 1}
        self.assertEqual(dup, {}, "every term belongs to one kind")

    def test_wordnet_kinds(self):
        """wordnet_kinds.json (the classifier identifier's map): every kind of the table, each synset
        once, each kind's own synsets under it, and ImageNet's chairs under chair."""
        with open(os.path.join(os.path.dirname(TABLE), "wordnet_kinds.json"), encoding="utf-8") as f:
            synsets = json.load(f)
        self.assertEqual(synsets["format"], "g2p-wordnet-kinds")
        self.assertEqual(list(synsets["kinds"]), [k["name"] for k in self.kinds])
        seen = {}
        for name, offsets in synsets["kinds"].items():
            self.assertEqual(offsets, sorted(offsets), name)
            for o in offsets:
                self.assertNotIn(o, seen, "synset %d under %s and %s" % (o, seen.get(o), name))
                seen[o] = name
        self.assertGreater(len(seen), 5000)
        # n03376595 folding chair, n04099969 rocking chair, n02791124 barber chair; n04579145 whiskey jug.
        for wnid, kind in [(3376595, "chair"), (4099969, "chair"), (2791124, "chair"), (4579145, "jug")]:
            self.assertEqual(seen.get(wnid), kind, wnid)

    def test_spot_facts(self):
        expect = {
            "recliner": "armchair", "sedan": "car", "hatchback": "car", "minivan": "car",
            "rocking chair": "chair", "couch": "sofa", "fridge": "refrigerator",
            "poodle": "dog", "lorry": "truck", "park bench": "bench", "tumbler": "glass",
            "saucepan": "pot", "grand piano": "grand piano", "upright piano": "piano",
            "washbasin": "washbasin", "microwave oven": "microwave", "cellphone": "cell phone",
            "hair dryer": "hair drier", "teddy bear": "teddy bear", "spiral staircase": "stairs",
            "kayak": "canoe", "floor lamp": "floor lamp", "desk lamp": "lamp", "bike": "bicycle",
        }
        for term, kind in expect.items():
            with self.subTest(term=term):
                self.assertEqual(self.owner.get(term), [kind])
        fridge = self.by_name["refrigerator"]
        self.assertGreater(sum(h["mass_fraction"] for h in fridge["hidden"]), 0)
        self.assertEqual(fridge["coco"], "refrigerator")
        car = self.by_name["car"]
        self.assertEqual(car["structure"], "hollow")
        self.assertTrue(0.3 <= sum(h["mass_fraction"] for h in car["hidden"]) <= 0.6)
        self.assertTrue(4.0 <= car["typical"]["longest_side_m"] <= 5.0)
        self.assertTrue(car["mass_kg"][0] >= 800 and car["mass_kg"][1] <= 2500)
        self.assertEqual(self.by_name["electric motor"]["structure"], "solid")
        self.assertEqual(self.by_name["sofa"]["structure"], "shell_with_contents")
        self.assertEqual(self.by_name["person"]["coco"], "person")
        self.assertTrue(1.5 <= self.by_name["person"]["typical"]["height_m"] <= 1.9)
        self.assertEqual(self.by_name["table"]["coco"], "dining table")
        self.assertEqual(self.by_name["sofa"]["coco"], "couch")
        self.assertEqual(self.by_name["chair"]["synsets"][0], "chair.n.01")
        self.assertEqual(self.by_name["chair"]["materials"][0]["class"], "Wood")

    def test_schema_file(self):
        with open(SCHEMA, encoding="utf-8") as f:
            schema = json.load(f)
        self.assertEqual(schema["$schema"], "https://json-schema.org/draft/2020-12/schema")
        kind = schema["$defs"]["kind"]
        self.assertEqual(set(kind["properties"]), set(self.kinds[0]) | {"coco"})
        self.assertEqual(kind["properties"]["materials"]["items"]["properties"]["class"]["enum"],
                         build_objects.CLASSES)
        try:
            import jsonschema  # optional; the table's own checks do not need it
        except ImportError:
            return
        jsonschema.Draft202012Validator(schema).validate(self.table)


if __name__ == "__main__":
    if not (os.path.isfile(os.path.join(WORDNET, "index.noun"))
            and os.path.isfile(os.path.join(WORDNET, "data.noun"))):
        print("SKIPPED: WordNet 3.0 is not installed at %s (apt-get install wordnet-base); "
              "objects.json cannot be rebuilt and checked" % WORDNET)
        sys.exit(0)
    unittest.main(verbosity=1)
