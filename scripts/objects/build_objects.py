#!/usr/bin/env python3
"""Build libg2p/data/objects.json, the table of everyday object kinds.

Inputs:
  scripts/objects/kinds.json   hand-written facts, one entry per kind (the source of truth)
  WordNet 3.0 noun database     Debian package wordnet-base: /usr/share/wordnet/{index,data}.noun

For every kind the script checks that each named synset exists, then generates the kind's
`terms`: the lemmas of its synsets and of all their hyponyms (transitively, unless the kind says
`"hyponyms": false`; a lemma only where its
most common sense lies under the kind, so "head" and "black" do not name a person nor "steel" a
sword, unless it is the kind's name or a hand-listed term), plus the kind's
hand-written `extra_terms`.  A term reached from several kinds goes to the most specific one
(the kind whose synset is the nearer hypernym of the term's synset); a term that is exactly a
lemma of a kind's own synset always belongs to that kind.

Beside it, libg2p/data/wordnet_kinds.json maps WordNet 3.0 noun synsets (by offset, as ImageNet's
ids "n03376595" write them) to kinds: every synset of a kind's closure (the same closure as its
terms), a synset reached from several kinds going to the nearest. The `classifier` identifier maps
a user's classifier's WordNet ids to kinds through it.

Usage:
  build_objects.py                 write libg2p/data/objects.json and wordnet_kinds.json
  build_objects.py --check         rebuild in memory; exit 1 if a committed file differs
  build_objects.py --wordnet DIR   read index.noun/data.noun from DIR instead
  build_objects.py --output FILE   write (or check) FILE instead, wordnet_kinds.json beside it

Python 3 standard library only; the WordNet database format is parsed here (see wndb(5WN)).
"""

import argparse
import collections
import gzip
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
KINDS = os.path.join(HERE, "kinds.json")
OUTPUT = os.path.join(ROOT, "libg2p", "data", "objects.json")
SYNSETS_OUTPUT = os.path.join(ROOT, "libg2p", "data", "wordnet_kinds.json")
DEFAULT_WORDNET = "/usr/share/wordnet"
PACKAGE = "wordnet-base"

GROUPS = ["furniture", "appliance", "vehicle", "tool", "toy", "electronics", "plant", "container",
          "kitchenware", "sports", "lighting", "instrument", "decor", "food", "animal", "person",
          "outdoor", "building_part", "other"]
CLASSES = ["Wood", "Rubber", "Fabric", "Organic", "Leather", "Metal", "Paper", "Plastic", "Glass",
           "Ceramic", "Stone", "Other"]
STRUCTURES = ["solid", "hollow", "shell_with_contents"]
WHERE = ["bottom", "centre", "spread"]
SOURCE_KEYS = ["size", "mass", "materials", "hidden"]
# The 80 COCO-2017 detection classes, spelled as COCO spells them.
COCO = ["person", "bicycle", "car", "motorcycle", "airplane", "bus", "train", "truck", "boat",
        "traffic light", "fire hydrant", "stop sign", "parking meter", "bench", "bird", "cat", "dog",
        "horse", "sheep", "cow", "elephant", "bear", "zebra", "giraffe", "backpack", "umbrella",
        "handbag", "tie", "suitcase", "frisbee", "skis", "snowboard", "sports ball", "kite",
        "baseball bat", "baseball glove", "skateboard", "surfboard", "tennis racket", "bottle",
        "wine glass", "cup", "fork", "knife", "spoon", "bowl", "banana", "apple", "sandwich",
        "orange", "broccoli", "carrot", "hot dog", "pizza", "donut", "cake", "chair", "couch",
        "potted plant", "bed", "dining table", "toilet", "tv", "laptop", "mouse", "remote",
        "keyboard", "cell phone", "microwave", "oven", "toaster", "sink", "refrigerator", "book",
        "clock", "vase", "scissors", "teddy bear", "hair drier", "toothbrush"]
MIN_TERM = 3
HAND_FIELDS = ["height_m", "longest_side_m", "typical", "mass_kg", "structure", "materials",
               "hidden", "sources"]


class BuildError(Exception):
    pass


# ---------------------------------------------------------------------------------------------
# WordNet
# ---------------------------------------------------------------------------------------------

class WordNet:
    """The noun part of a WordNet 3.0 database: senses per lemma and the hyponym graph."""

    def __init__(self, directory):
        index = os.path.join(directory, "index.noun")
        data = os.path.join(directory, "data.noun")
        if not (os.path.isfile(index) and os.path.isfile(data)):
            raise BuildError(
                "WordNet 3.0 noun database not found in %s (need index.noun and data.noun); "
                "install the Debian package '%s' (apt-get install --no-install-recommends %s) "
                "or pass --wordnet DIR" % (directory, PACKAGE, PACKAGE))
        self.senses = {}        # lemma -> [offset, ...] in sense order (sense n = position n-1)
        with open(index, encoding="utf-8") as f:
            for line in f:
                if line.startswith(" "):          # licence header
                    continue
                p = line.split()
                lemma, synset_cnt, p_cnt = p[0], int(p[2]), int(p[3])
                offsets = p[4 + p_cnt + 2:]        # after the pointer symbols, sense_cnt, tagsense_cnt
                if len(offsets) != synset_cnt:
                    raise BuildError("index.noun: malformed line for %r" % lemma)
                self.senses[lemma] = [int(o) for o in offsets]
        self.words = {}         # offset -> [lemma, ...] as written in data.noun
        self.hyponyms = {}      # offset -> [offset, ...] ("~" pointers to nouns; no instances)
        self.hypernyms = {}     # offset -> [offset, ...] ("@" pointers)
        with open(data, encoding="utf-8") as f:
            for line in f:
                if line.startswith(" "):
                    continue
                head = line.split("|", 1)[0].split()
                offset = int(head[0])
                w_cnt = int(head[3], 16)
                words = []
                for i in range(w_cnt):
                    words.append(head[4 + 2 * i])
                k = 4 + 2 * w_cnt
                p_cnt = int(head[k])
                k += 1
                hypo, hyper = [], []
                for _ in range(p_cnt):
                    symbol, target, pos = head[k], int(head[k + 1]), head[k + 2]
                    k += 4
                    if pos != "n":
                        continue
                    if symbol == "~":
                        hypo.append(target)
                    elif symbol == "@":
                        hyper.append(target)
                self.words[offset] = words
                self.hyponyms[offset] = hypo
                self.hypernyms[offset] = hyper

    @staticmethod
    def key(lemma):
        return lemma.lower().replace(" ", "_")

    def sense_number(self, lemma, offset):
        offs = self.senses.get(self.key(lemma), [])
        return offs.index(offset) + 1 if offset in offs else 99

    def canonical_name(self, offset):
        """The lemma.n.NN name NLTK gives a synset: its first lemma and that lemma's sense number."""
        first = self.words[offset][0]
        return "%s.n.%02d" % (first.lower(), self.sense_number(first, offset))

    def resolve(self, name):
        """'lemma.n.NN' -> offset, or None."""
        parts = name.rsplit(".", 2)
        if len(parts) != 3 or parts[1] != "n" or not parts[2].isdigit():
            return None
        offs = self.senses.get(self.key(parts[0]))
        n = int(parts[2])
        if not offs or n < 1 or n > len(offs):
            return None
        return offs[n - 1]

    def closure(self, offset):
        """Breadth-first hyponym closure: {offset: distance} including the synset itself (0)."""
        dist = {offset: 0}
        queue = collections.deque([offset])
        while queue:
            o = queue.popleft()
            for h in self.hyponyms.get(o, []):
                if h not in dist:
                    dist[h] = dist[o] + 1
                    queue.append(h)
        return dist


def debian_version(directory):
    """Version of the Debian package that provides the database, or 'unknown'."""
    if os.path.realpath(directory) != os.path.realpath(DEFAULT_WORDNET):
        return "unknown"
    try:
        out = subprocess.run(["dpkg-query", "-W", "-f=${Version}", PACKAGE], capture_output=True,
                             text=True, check=False, timeout=30)
        if out.returncode == 0 and out.stdout.strip():
            return out.stdout.strip()
    except (OSError, subprocess.SubprocessError):
        pass
    changelog = "/usr/share/doc/%s/changelog.Debian.gz" % PACKAGE
    try:
        with gzip.open(changelog, "rt", encoding="utf-8") as f:
            first = f.readline()
        return first.split("(", 1)[1].split(")", 1)[0]
    except (OSError, IndexError):
        return "unknown"


# ---------------------------------------------------------------------------------------------
# Terms
# ---------------------------------------------------------------------------------------------

def term_of(lemma):
    return lemma.lower().replace("_", " ")


def build_terms(kinds, wn):
    """Assign every reached term to exactly one kind; returns {kind index: sorted terms}."""
    own = collections.defaultdict(list)      # term -> [(name-match, sense, kind idx)] own synset lemmas
    reach = {}                               # term -> best (distance, sense, kind idx)
    extra = {}                               # term -> kind idx
    for ki, kind in enumerate(kinds):
        for name in kind["synsets"]:
            root = wn.resolve(name)
            # "hyponyms": false keeps a kind to its own synsets' lemmas: WordNet's thousands of kinds
            # of person ("white", "ruler", "guard", "passenger") are what node names say of parts.
            closure = wn.closure(root) if kind.get("hyponyms", True) else {root: 0}
            for off, d in closure.items():
                for lemma in wn.words[off]:
                    t = term_of(lemma)
                    s = wn.sense_number(lemma, off)
                    # A word counts only where its most common sense is in this kind: "head" (a leader,
                    # under person) means a body part first, "black" a colour, "wood" a material, and a
                    # sword's own "steel" the alloy; the kind's name and its hand-listed terms stay.
                    first = wn.senses.get(wn.key(lemma), [off])[0]
                    hand = t == kind["name"] or t in [e.lower() for e in kind.get("extra_terms", [])]
                    if first not in closure and not hand:
                        continue
                    cand = (d, s, ki)
                    if t not in reach or cand < reach[t]:
                        reach[t] = cand
                    if d == 0:
                        own[t].append((0 if t == kind["name"] else 1, s, ki))
        for t in kind.get("extra_terms", []) + [kind["name"]]:
            t = t.lower()
            if t in extra and extra[t] != ki:
                raise BuildError("term %r is listed by both %r and %r" %
                                 (t, kinds[extra[t]]["name"], kind["name"]))
            extra[t] = ki
    owner = {}
    conflicts = []
    for t, (_, _, ki) in reach.items():
        owner[t] = ki
    for t, ki in extra.items():
        owner[t] = ki
    for t, cands in own.items():
        best = min(cands)[2]
        if t in extra and extra[t] != best and (kinds[extra[t]]["name"] == t
                                                 or extra[t] in [c[2] for c in cands]):
            best = extra[t]          # a kind's own name, or a hand choice between own lemmas, wins
        elif t in extra and extra[t] != best:
            conflicts.append("extra term %r of %r is a lemma of %r's own synset %s" % (
                t, kinds[extra[t]]["name"], kinds[best]["name"], ", ".join(kinds[best]["synsets"])))
        owner[t] = best
    if conflicts:
        raise BuildError("\n".join(conflicts))
    terms = collections.defaultdict(list)
    for t, ki in owner.items():
        if len(t) >= MIN_TERM:
            terms[ki].append(t)
    return {ki: sorted(set(ts)) for ki, ts in terms.items()}


def build_synset_kinds(kinds, wn):
    """{kind name: sorted offsets}: every synset of a kind's closure, each to its nearest kind."""
    best = {}                                # offset -> (distance, kind idx)
    for ki, kind in enumerate(kinds):
        for name in kind["synsets"]:
            root = wn.resolve(name)
            closure = wn.closure(root) if kind.get("hyponyms", True) else {root: 0}
            for off, d in closure.items():
                if off not in best or (d, ki) < best[off]:
                    best[off] = (d, ki)
    out = collections.OrderedDict((k["name"], []) for k in kinds)
    for off, (_, ki) in best.items():
        out[kinds[ki]["name"]].append(off)
    return collections.OrderedDict((name, sorted(offs)) for name, offs in out.items())


# ---------------------------------------------------------------------------------------------
# Validation (the same rules as libg2p/data/objects.schema.json, plus what a schema cannot say)
# ---------------------------------------------------------------------------------------------

def _num(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _range(where, r, errors, positive=True):
    if not (isinstance(r, list) and len(r) == 2 and all(_num(v) for v in r)):
        errors.append("%s: must be [lo, hi] numbers" % where)
        return False
    if positive and not r[0] > 0:
        errors.append("%s: lo must be > 0" % where)
    if not r[0] <= r[1]:
        errors.append("%s: lo must be <= hi" % where)
    return True


def validate_kind(k, errors):
    n = k.get("name", "?")
    w = "kind %r" % n
    if not (isinstance(k.get("name"), str) and k["name"] == k["name"].lower() and k["name"].strip()):
        errors.append("%s: name must be a non-empty lowercase string" % w)
    if k.get("group") not in GROUPS:
        errors.append("%s: group %r is not one of %s" % (w, k.get("group"), GROUPS))
    if not (isinstance(k.get("synsets"), list) and k["synsets"]):
        errors.append("%s: needs at least one synset" % w)
    if "coco" in k and k["coco"] not in COCO:
        errors.append("%s: coco %r is not a COCO-2017 class" % (w, k["coco"]))
    if "terms" in k and not (isinstance(k["terms"], list) and all(
            isinstance(t, str) and len(t) >= MIN_TERM for t in k["terms"])
            and k["terms"] == sorted(set(k["terms"]))):
        errors.append("%s: terms must be sorted unique strings of >= %d characters" % (w, MIN_TERM))
    ok_h = _range(w + " height_m", k.get("height_m"), errors)
    ok_l = _range(w + " longest_side_m", k.get("longest_side_m"), errors)
    ok_m = _range(w + " mass_kg", k.get("mass_kg"), errors)
    if ok_m and k["mass_kg"][0] > 0 and k["mass_kg"][1] < 1.5 * k["mass_kg"][0] - 1e-9:
        errors.append("%s: mass_kg range narrower than 1.5x" % w)
    typ = k.get("typical")
    if not (isinstance(typ, dict) and set(typ) == {"height_m", "longest_side_m"}
            and all(_num(v) and v > 0 for v in typ.values())):
        errors.append("%s: typical must be {height_m, longest_side_m} positive numbers" % w)
    elif ok_h and ok_l:
        if not k["height_m"][0] <= typ["height_m"] <= k["height_m"][1]:
            errors.append("%s: typical height %s outside height_m %s" % (w, typ["height_m"], k["height_m"]))
        if not k["longest_side_m"][0] <= typ["longest_side_m"] <= k["longest_side_m"][1]:
            errors.append("%s: typical longest side %s outside longest_side_m %s" % (
                w, typ["longest_side_m"], k["longest_side_m"]))
        if typ["height_m"] > typ["longest_side_m"] + 1e-9:
            errors.append("%s: typical height exceeds typical longest side" % w)
        if k["height_m"][1] > k["longest_side_m"][1] + 1e-9:
            errors.append("%s: height_m hi exceeds longest_side_m hi" % w)
    if "hyponyms" in k and not isinstance(k["hyponyms"], bool):
        errors.append("%s: hyponyms must be true or false" % w)
    if k.get("structure") not in STRUCTURES:
        errors.append("%s: structure must be one of %s" % (w, STRUCTURES))
    mats = k.get("materials")
    if not (isinstance(mats, list) and 1 <= len(mats) <= 5):
        errors.append("%s: materials must have 1-5 entries" % w)
    else:
        for m in mats:
            if not (isinstance(m, dict) and {"role", "class"} <= set(m) <= {"role", "class", "max_share"}
                    and isinstance(m["role"], str) and m["role"] and m["class"] in CLASSES):
                errors.append("%s: bad material %r (class must be one of %s)" % (w, m, CLASSES))
            elif "max_share" in m and not (_num(m["max_share"]) and 0 < m["max_share"] <= 1):
                errors.append("%s: max_share of %r must be in (0, 1]" % (w, m["role"]))
    hid = k.get("hidden")
    if not isinstance(hid, list):
        errors.append("%s: hidden must be a list" % w)
    else:
        total = 0.0
        for h in hid:
            if not (isinstance(h, dict) and set(h) == {"what", "mass_fraction", "where"}
                    and isinstance(h["what"], str) and h["what"] and _num(h["mass_fraction"])
                    and 0 < h["mass_fraction"] <= 0.9 and h["where"] in WHERE):
                errors.append("%s: bad hidden entry %r" % (w, h))
            else:
                total += h["mass_fraction"]
        if total > 0.9 + 1e-9:
            errors.append("%s: hidden mass fractions sum to %.2f > 0.9" % (w, total))
    src = k.get("sources")
    if not (isinstance(src, dict) and set(src) == set(SOURCE_KEYS)
            and all(isinstance(v, str) and v.strip() for v in src.values())):
        errors.append("%s: sources must have non-empty strings for %s" % (w, SOURCE_KEYS))


def validate_table(table):
    errors = []
    if table.get("format") != "g2p-object-table" or table.get("version") != 1:
        errors.append("format/version must be g2p-object-table/1")
    for key in ("about", "wordnet"):
        if not isinstance(table.get(key), str) or not table[key]:
            errors.append("%s must be a non-empty string" % key)
    kinds = table.get("kinds")
    if not isinstance(kinds, list) or not kinds:
        errors.append("kinds must be a non-empty list")
        return errors
    names, cocos, synsets = {}, {}, {}
    for k in kinds:
        validate_kind(k, errors)
        n = k.get("name")
        if n in names:
            errors.append("duplicate kind name %r" % n)
        names[n] = True
        if "coco" in k:
            if k["coco"] in cocos:
                errors.append("COCO class %r mapped by both %r and %r" % (k["coco"], cocos[k["coco"]], n))
            cocos[k["coco"]] = n
        for s in k.get("synsets", []):
            if s in synsets:
                errors.append("synset %s used by both %r and %r" % (s, synsets[s], n))
            synsets[s] = n
    missing = [c for c in COCO if c not in cocos]
    if missing:
        errors.append("COCO classes with no kind: %s" % ", ".join(missing))
    return errors


# ---------------------------------------------------------------------------------------------
# Build
# ---------------------------------------------------------------------------------------------

def check_synsets(kinds, wn):
    errors = []
    seen = {}
    for k in kinds:
        for s in k.get("synsets", []):
            off = wn.resolve(s)
            if off is None:
                errors.append("kind %r: synset %s is not a WordNet 3.0 noun sense" % (k["name"], s))
                continue
            canon = wn.canonical_name(off)
            if canon != s:
                errors.append("kind %r: synset %s is WordNet's %s (%s); name it %s" % (
                    k["name"], s, canon, ", ".join(wn.words[off]), canon))
            if off in seen:
                errors.append("kind %r: synset %s is already used by %r" % (k["name"], s, seen[off]))
            seen[off] = k["name"]
    if errors:
        raise BuildError("\n".join(errors))


def build(wordnet_dir):
    with open(KINDS, encoding="utf-8") as f:
        src = json.load(f)
    wn = WordNet(wordnet_dir)
    kinds = src["kinds"]
    check_synsets(kinds, wn)
    terms = build_terms(kinds, wn)
    out_kinds = []
    for ki, k in enumerate(kinds):
        o = collections.OrderedDict()
        o["name"] = k["name"]
        o["group"] = k["group"]
        o["synsets"] = list(k["synsets"])
        if "coco" in k:
            o["coco"] = k["coco"]
        o["terms"] = terms.get(ki, [])
        for f in HAND_FIELDS:
            o[f] = k[f]
        out_kinds.append(o)
    table = collections.OrderedDict()
    table["format"] = "g2p-object-table"
    table["version"] = 1
    table["about"] = src["about"]
    table["wordnet"] = "WordNet 3.0 (Debian %s %s)" % (PACKAGE, debian_version(wordnet_dir))
    table["kinds"] = out_kinds
    errors = validate_table(table)
    if errors:
        raise BuildError("objects table is invalid:\n  " + "\n  ".join(errors))
    synsets = collections.OrderedDict()
    synsets["format"] = "g2p-wordnet-kinds"
    synsets["version"] = 1
    synsets["about"] = ("WordNet 3.0 noun synsets by offset (ImageNet's n-ids without the 'n') under each "
                        "kind of objects.json; built by scripts/objects/build_objects.py")
    synsets["wordnet"] = table["wordnet"]
    synsets["kinds"] = build_synset_kinds(kinds, wn)
    return table, synsets


def render(value, indent=0):
    """JSON with 1-space indentation; lists of scalars and the small material/hidden objects on one line."""
    pad = " " * indent
    if isinstance(value, dict):
        if not value:
            return "{}"
        if indent >= 2 and all(not isinstance(v, (dict, list)) for v in value.values()) and len(value) <= 3:
            return json.dumps(value, ensure_ascii=False)
        items = ['%s "%s": %s' % (pad, k, render(v, indent + 1)) for k, v in value.items()]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(value, list):
        if all(not isinstance(v, (dict, list)) for v in value) or \
                all(isinstance(v, dict) and all(not isinstance(x, (dict, list)) for x in v.values())
                    and len(v) <= 3 for v in value):
            return json.dumps(value, ensure_ascii=False)
        items = [pad + " " + render(v, indent + 1) for v in value]
        return "[\n" + ",\n".join(items) + "\n" + pad + "]"
    return json.dumps(value, ensure_ascii=False)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true",
                    help="rebuild in memory and exit 1 if the output file differs")
    ap.add_argument("--wordnet", default=DEFAULT_WORDNET, metavar="DIR",
                    help="directory with WordNet 3.0 index.noun and data.noun (default %(default)s)")
    ap.add_argument("--output", default=OUTPUT, metavar="FILE", help="default %(default)s")
    args = ap.parse_args(argv)
    try:
        table, synsets = build(args.wordnet)
    except BuildError as e:
        print("build_objects: error: %s" % e, file=sys.stderr)
        return 2
    if args.check:
        try:
            with open(args.output, encoding="utf-8") as f:
                old_text = f.read()
            old = json.loads(old_text)
        except (OSError, ValueError) as e:
            print("build_objects: %s cannot be read (%s); run scripts/objects/build_objects.py"
                  % (args.output, e), file=sys.stderr)
            return 1
        if old.get("wordnet") != table["wordnet"]:
            # Same WordNet 3.0 data under another Debian revision: compare the rest.
            print("build_objects: note: %s was built from %s, this machine has %s"
                  % (args.output, old.get("wordnet"), table["wordnet"]))
            table["wordnet"] = old.get("wordnet")
        new_text = render(table) + "\n"
        if new_text != old_text:
            old_kinds = {k.get("name"): k for k in old.get("kinds", [])}
            diffs = [k["name"] for k in table["kinds"] if old_kinds.get(k["name"]) != json.loads(json.dumps(k))]
            print("build_objects: %s is out of date with scripts/objects/kinds.json and WordNet "
                  "(kinds that differ: %s); run scripts/objects/build_objects.py and commit the result"
                  % (args.output, ", ".join(diffs[:20]) or "formatting/header only"), file=sys.stderr)
            return 1
        synsets_output = os.path.join(os.path.dirname(args.output), os.path.basename(SYNSETS_OUTPUT))
        try:
            with open(synsets_output, encoding="utf-8") as f:
                old_synsets = json.load(f)
        except (OSError, ValueError) as e:
            print("build_objects: %s cannot be read (%s); run scripts/objects/build_objects.py"
                  % (synsets_output, e), file=sys.stderr)
            return 1
        synsets["wordnet"] = old_synsets.get("wordnet")
        if old_synsets != json.loads(json.dumps(synsets)):
            print("build_objects: %s is out of date with scripts/objects/kinds.json and WordNet; run "
                  "scripts/objects/build_objects.py and commit the result" % synsets_output, file=sys.stderr)
            return 1
        print("build_objects: %s is up to date (%d kinds), %s too (%d synsets)"
              % (args.output, len(table["kinds"]), synsets_output,
                 sum(len(v) for v in synsets["kinds"].values())))
        return 0
    os.makedirs(os.path.dirname(args.output), exist_ok=True)
    with open(args.output, "w", encoding="utf-8") as f:
        f.write(render(table) + "\n")
    synsets_output = os.path.join(os.path.dirname(args.output), os.path.basename(SYNSETS_OUTPUT))
    with open(synsets_output, "w", encoding="utf-8") as f:
        f.write(render(synsets) + "\n")
    n_terms = sum(len(k["terms"]) for k in table["kinds"])
    n_synsets = sum(len(v) for v in synsets["kinds"].values())
    print("build_objects: wrote %s (%d kinds, %d terms) and %s (%d synsets)"
          % (args.output, len(table["kinds"]), n_terms, synsets_output, n_synsets))
    return 0


if __name__ == "__main__":
    sys.exit(main())
