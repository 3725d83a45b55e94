"""The Blender add-on (blender/g2p_blender) in Debian's Blender, headless:

  BLENDER_USER_SCRIPTS=$(mktemp -d) BLENDER_USER_CONFIG=$(mktemp -d) \
  blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_addon.py -- \
      --module build/python --hammer examples/data/hammer.obj --asset ../shared/assets/X/X.glb [--segmenter S] \
      [--same-as-run ../shared/assets/Y/Y.glb]

Installs the add-on from its zip into BLENDER_USER_SCRIPTS (without it, registers it from the
source tree), checks the error when the g2p module is not found, then imports each model, runs the add-on's operator on it, checks the parts and
masses against the Python pipeline's run of the same file with the same
options (what `g2p run` reports), checks the rigid body settings, and drops
the asset onto a plane in Blender's rigid body world: it must come to rest,
upright; each --same-as-run model gets the library's parts and masses with the
default segmenter. Run outside Blender, it exits 77 (skipped) saying why."""

import argparse
import json
import math
import os
import sys
import tempfile
import time
import zipfile

try:
    import bpy
except ImportError:
    reason = sys.argv[sys.argv.index("--skip-reason") + 1] if "--skip-reason" in sys.argv else \
        "run inside Blender (blender -b --python tests/blender/test_addon.py -- ...)"
    print("SKIPPED: " + reason)
    sys.exit(77)

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="test_addon.py")
    parser.add_argument("--module", default="", help="folder of the g2p module (else PYTHONPATH)")
    parser.add_argument("--hammer", default=os.path.join(REPO, "examples", "data", "hammer.obj"))
    parser.add_argument("--asset", required=True, help="a shared asset (.glb)")
    parser.add_argument("--segmenter", default="", help="for the asset; '' = the library's default")
    parser.add_argument("--same-as-run", action="append", default=[], metavar="GLB",
                        help="a model whose parts and masses through the add-on, with the library's default "
                             "segmenter, must be the library's run of the file (repeatable)")
    return parser.parse_args(argv)


def check(condition, message):
    if not condition:
        raise AssertionError(message)


def clear_scene():
    """An empty scene, the add-on still enabled (read_factory_settings would reset the preferences)."""
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob)
    for data in (bpy.data.meshes, bpy.data.materials, bpy.data.collections, bpy.data.images):
        for item in list(data):
            data.remove(item)
    scene = bpy.context.scene
    if scene.rigidbody_world is not None:
        bpy.ops.rigidbody.world_remove()
    scene.frame_set(1)


def import_model(path):
    before = set(bpy.data.objects)
    if path.endswith(".obj"):
        bpy.ops.wm.obj_import(filepath=path)
    else:  # on Debian 12's Blender 3.4.1 this works because the add-on puts numpy.bool back (register())
        bpy.ops.import_scene.gltf(filepath=path)
    objects = [ob for ob in bpy.data.objects if ob not in before and ob.type == "MESH"]
    check(objects, f"{path}: no mesh imported")
    bpy.ops.object.select_all(action="DESELECT")
    for ob in objects:
        ob.select_set(True)
    bpy.context.view_layer.objects.active = objects[0]
    return objects


def reference(g2p, path, segmenter):
    """The library's run of the file (what `g2p run` writes to report.json)."""
    from g2p_blender import core
    options = core.pipeline_options(g2p, segmenter)
    return g2p.Pipeline(options).run_file(path)


def run_addon(path, segmenter):
    clear_scene()
    import_model(path)
    bpy.context.scene.g2p.segmenter = segmenter or "DEFAULT"
    t = time.time()
    outcome = bpy.ops.g2p.make_parts(synchronous=True)
    check(outcome == {"FINISHED"}, f"{path}: the operator returned {outcome}")
    bodies = [ob for ob in bpy.data.objects if "g2p_sources" in ob]
    check(len(bodies) == 1, f"{path}: expected one body object, got {len(bodies)}")
    print(f"{os.path.basename(path)}: the add-on's run took {time.time() - t:.1f} s")
    return bodies[0]


def check_parts(path, body, expected):
    parts = sorted((ob for ob in body.children if "g2p_class" in ob), key=lambda ob: ob["g2p_part"])
    got = [(ob["g2p_class"], ob["g2p_mass_kg"]) for ob in parts]
    want = [(p["class"], p["mass_kg"]) for p in expected.properties]
    print(f"{os.path.basename(path)}: add-on {got}\n  library {want}")
    check(len(got) == len(want), f"{path}: {len(got)} parts, the library's run has {len(want)}")
    for (c, m), (wc, wm) in zip(got, want):
        check(c == wc, f"{path}: part class {c}, the library's run has {wc}")
        check(math.isclose(m, wm, rel_tol=2e-3), f"{path}: {c} part of {m} kg, the library's run has {wm} kg")
    check(math.isclose(body["g2p_mass_kg"], expected.mass_kg, rel_tol=2e-3),
          f"{path}: total {body['g2p_mass_kg']} kg, the library's {expected.mass_kg} kg")


def check_rigid_body(path, body, expected):
    rb = body.rigid_body
    check(rb is not None and rb.type == "ACTIVE" and rb.collision_shape == "COMPOUND",
          f"{path}: the body has no active COMPOUND rigid body")
    check(math.isclose(rb.mass, expected.mass_kg, rel_tol=2e-3), f"{path}: rigid body mass {rb.mass} kg")
    check(0 < rb.friction <= 2 and 0 <= rb.restitution <= 1, f"{path}: friction {rb.friction}, "
          f"restitution {rb.restitution}")
    hulls = [ob for ob in body.children if ob.rigid_body is not None]
    check(hulls and all(ob.rigid_body.collision_shape == "CONVEX_HULL" for ob in hulls),
          f"{path}: the convex hulls are not the compound's CONVEX_HULL children")
    expected_hulls = sum(len(c.hulls) for c in expected.collision)
    check(len(hulls) == expected_hulls, f"{path}: {len(hulls)} hulls, the library's run has {expected_hulls}")
    centre = [ob for ob in body.children if ob.type == "EMPTY"]
    check(len(centre) == 1 and centre[0].location.length < 1e-9, f"{path}: no empty at the centre of mass")


def lowest_z(body):
    return min((ob.matrix_world @ v.co).z for ob in body.children if ob.type == "MESH" and ob.rigid_body
               for v in ob.data.vertices)


def drop(path, body, seconds=2.0, height_m=0.05):
    """Drops the body onto a plane; it must come to rest on it, upright."""
    scene = bpy.context.scene
    floor_z = lowest_z(body) - height_m
    bpy.ops.mesh.primitive_plane_add(size=20, location=(0, 0, floor_z))
    plane = bpy.context.active_object
    with bpy.context.temp_override(object=plane, active_object=plane, selected_objects=[plane]):
        bpy.ops.rigidbody.object_add(type="PASSIVE")
    world = scene.rigidbody_world
    fps = scene.render.fps
    frames = int(seconds * fps)
    world.point_cache.frame_start = 1
    world.point_cache.frame_end = frames + 1
    scene.frame_start, scene.frame_end = 1, frames + 1
    heights = []
    for frame in range(1, frames + 2):
        scene.frame_set(frame)
        heights.append((body.matrix_world.translation.z, body.matrix_world.to_3x3().col[2].z))
    up = heights[-1][1]
    rest = abs(heights[-1][0] - heights[-int(0.25 * fps)][0])
    gap = lowest_z(body) - floor_z
    print(f"{os.path.basename(path)}: after {seconds} s the centre of mass is {heights[-1][0] - floor_z:.4f} m "
          f"above the plane, lowest point {gap:.4f} m, moved {rest:.2e} m in the last 0.25 s, up axis z {up:.4f}")
    check(heights[-1][0] < heights[0][0] - 0.5 * height_m, f"{path}: the object did not fall")
    check(rest < 1e-3, f"{path}: still moving ({rest} m in the last 0.25 s)")
    check(-0.01 < gap < 0.01, f"{path}: its lowest point is {gap} m from the plane after the drop")
    check(up > math.cos(math.radians(5)), f"{path}: not upright (its up axis is {math.degrees(math.acos(up)):.1f} deg "
                                          "off vertical)")


def install_addon(work):
    """Installs the add-on as a user does: its zip through Preferences' Install, then enabled.
    The user folders are the test's own (BLENDER_USER_SCRIPTS, BLENDER_USER_CONFIG from ctest)."""
    import addon_utils
    zip_path = os.path.join(work, "g2p_blender.zip")
    with zipfile.ZipFile(zip_path, "w") as z:
        package = os.path.join(REPO, "blender", "g2p_blender")
        for name in sorted(os.listdir(package)):
            if name.endswith(".py"):
                z.write(os.path.join(package, name), os.path.join("g2p_blender", name))
    bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
    addon_utils.enable("g2p_blender", default_set=True, handle_error=None)
    check("g2p_blender" in bpy.context.preferences.addons, "the add-on did not enable from its zip")
    return bpy.context.preferences.addons["g2p_blender"].preferences


def expect_error(what, words, **operator_args):
    """The operator must fail with an ERROR report holding `words` and leave the scene as it was."""
    objects, meshes = len(bpy.data.objects), len(bpy.data.meshes)
    collections = len(bpy.data.collections)
    try:
        bpy.ops.g2p.make_parts(synchronous=True, **operator_args)
        raise AssertionError(f"{what}: the operator did not fail")
    except RuntimeError as e:  # bpy.ops raises the operator's ERROR report
        check(words in str(e), f"{what}: the error says {str(e)!r}, not {words!r}")
        print(f"{what}: {str(e).splitlines()[0][:160]}")
    check((len(bpy.data.objects), len(bpy.data.meshes), len(bpy.data.collections)) == (objects, meshes, collections),
          f"{what}: the failed run changed the scene")


def select_sources(body):
    bpy.ops.object.select_all(action="DESELECT")
    for name in json.loads(body["g2p_sources"]):
        bpy.data.objects[name].hide_set(False)
        bpy.data.objects[name].select_set(True)


def main():
    args = parse_args()
    start = time.time()
    if not os.path.exists(args.asset):
        print(f"SKIPPED: the shared asset {args.asset} is missing (G2P_SHARED_ASSETS)")
        sys.exit(77)
    if os.environ.get("BLENDER_USER_SCRIPTS"):
        with tempfile.TemporaryDirectory() as work:
            prefs = install_addon(work)
    else:  # not into the user's own add-ons: registered from the source tree
        print("BLENDER_USER_SCRIPTS is not set: the add-on is registered from blender/, not installed from its zip")
        sys.path.insert(0, os.path.join(REPO, "blender"))
        import g2p_blender
        g2p_blender.register()
        prefs = argparse.Namespace(module_path="")
        if args.module:
            sys.path.insert(0, args.module)

    # Without the module: a clear error, nothing changed (unless g2p is installed system-wide).
    clear_scene()
    import_model(args.hammer)
    try:
        import g2p  # noqa: F401
        print("g2p imports without the add-on's module folder: the missing-module check is skipped")
    except ImportError:
        expect_error("no module", "cannot import the g2p Python module")
    prefs.module_path = args.module or next(iter(os.environ.get("PYTHONPATH", "").split(os.pathsep)), "")
    from g2p_blender import core
    g2p = core.import_g2p(prefs.module_path)  # as the add-on finds it

    # The hammer: parts and masses as the library's, rigid body settings.
    hammer = run_addon(args.hammer, "")
    expected = reference(g2p, args.hammer, "")
    check_parts(args.hammer, hammer, expected)
    check_rigid_body(args.hammer, hammer, expected)

    # A correction: the handle's density; the stages after it run again and the body is replaced.
    wood = next(ob for ob in hammer.children if ob.get("g2p_class") == "Wood")
    wood_mass, wood_density = wood["g2p_mass_kg"], wood["g2p_density_kg_m3"]
    bpy.context.view_layer.objects.active = wood
    wood.g2p_correction.density_kg_m3 = 1000.0
    check(bpy.ops.g2p.correct(synchronous=True) == {"FINISHED"}, "the correction failed")
    bodies = [ob for ob in bpy.data.objects if "g2p_sources" in ob]
    check(len(bodies) == 1 and bodies[0].name == "hammer (g2p)", "the corrected run did not replace the body")
    hammer = bodies[0]
    wood = next(ob for ob in hammer.children if ob.get("g2p_class") == "Wood")
    check(math.isclose(wood["g2p_mass_kg"], wood_mass * 1000.0 / wood_density, rel_tol=1e-6),
          f"corrected handle: {wood['g2p_mass_kg']} kg, expected {wood_mass * 1000.0 / wood_density} kg")
    check(math.isclose(hammer.rigid_body.mass, hammer["g2p_mass_kg"], rel_tol=1e-6),
          "the rigid body's mass was not updated")
    stages = json.loads(hammer["g2p_stages"])
    check(stages[0] == "properties", f"the density correction ran {stages}, not from properties on")
    print(f"corrected handle: {wood_mass:.4f} kg at {wood_density} kg/m^3 -> {wood['g2p_mass_kg']:.4f} kg at 1000")
    # A second correction, the class: it accumulates on the first (whose density still stands).
    bpy.context.view_layer.objects.active = wood
    wood.g2p_correction.klass = "Plastic"
    check(bpy.ops.g2p.correct(synchronous=True) == {"FINISHED"}, "the class correction failed")
    hammer = next(ob for ob in bpy.data.objects if "g2p_sources" in ob)
    classes = sorted(ob["g2p_class"] for ob in hammer.children if "g2p_class" in ob)
    check(classes == ["Metal", "Plastic"], f"after the class correction the parts are {classes}")
    handle = next(ob for ob in hammer.children if ob.get("g2p_class") == "Plastic")
    check(math.isclose(handle["g2p_density_kg_m3"], 1000.0), f"the handle's density is {handle['g2p_density_kg_m3']}")
    check(len(json.loads(hammer["g2p_corrections"])) == 2, "the corrections did not accumulate")
    stages = json.loads(hammer["g2p_stages"])
    check(stages[0] == "complete", f"the class correction ran {stages}, not from complete on")

    # Failures change nothing: a correction the library refuses, a run that fails.
    select_sources(hammer)
    expect_error("bad correction", "unknown class 'NoSuchClass'", corrections='[{"faces": [0], "class": "NoSuchClass"}]')
    bpy.context.scene.g2p.segmenter = "oracle"  # needs a labels file: the run fails
    expect_error("failed run", "g2p run failed")
    bpy.context.scene.g2p.segmenter = "DEFAULT"
    stray = bpy.data.objects.new("stray", bpy.data.meshes.new("stray"))  # in no scene
    expect_error("outside the view layer", "not in the current view layer", sources='["stray"]')
    bpy.data.objects.remove(stray)

    # The real size in the panel (--height): the parts come out 0.5 m tall, the input untouched.
    select_sources(hammer)
    source_height = max(ob.dimensions.z for ob in bpy.context.selected_objects)
    bpy.context.scene.g2p.height_m = 0.5
    check(bpy.ops.g2p.make_parts(synchronous=True) == {"FINISHED"}, "the run with a height failed")
    bpy.context.scene.g2p.height_m = 0.0
    tall = bpy.context.view_layer.objects.active
    heights = [(ob.matrix_world @ v.co).z for ob in tall.children if "g2p_class" in ob for v in ob.data.vertices]
    check(abs(max(heights) - min(heights) - 0.5) < 0.01, f"with Height 0.5 m the parts span {max(heights) - min(heights):.4f} m")
    check(abs(max(ob.dimensions.z for ob in bpy.data.objects if ob.name in json.loads(tall["g2p_sources"]))
              - source_height) < 1e-9, "the run with a height changed the input")
    print(f"height 0.5 m: the parts span {max(heights) - min(heights):.4f} m (the input {source_height:.4f} m)")

    # The shared asset: the same checks, and the drop.
    asset = run_addon(args.asset, args.segmenter)
    expected = reference(g2p, args.asset, args.segmenter)
    check_parts(args.asset, asset, expected)
    check_rigid_body(args.asset, asset, expected)
    drop(args.asset, asset)

    # Models whose look is in textures (metallic-roughness, emissive, normal, occlusion): through
    # Blender's exporter the library sees what `g2p run` sees in the file.
    for path in args.same_as_run:
        if not os.path.exists(path):
            print(f"{path} is missing: not compared")
            continue
        body = run_addon(path, "")
        check_parts(path, body, reference(g2p, path, ""))
    print(f"OK in {time.time() - start:.1f} s")


if __name__ == "__main__":
    try:
        main()
    except Exception:
        import traceback
        traceback.print_exc()
        sys.exit(1)
    sys.exit(0)
