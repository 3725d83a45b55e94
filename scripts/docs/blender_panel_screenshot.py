"""docs/images/blender-panel.png: the add-on's panel after a run on the hammer,
in Blender with a window (Xvfb), through the interactive path (the modal
operator and its worker thread). Not a ctest; run from the repository root:

  BLENDER_USER_CONFIG=$(mktemp -d) G2P_PYTHON=build/python xvfb-run -a -s "-screen 0 1600x1000x24" \
      blender --enable-event-simulate --python scripts/docs/blender_panel_screenshot.py

(a fresh user config without a splash: the script saves one on its first start and asks to be run
again). Event simulation clicks the sidebar's g2p tab at the position it has on a 1600x1000 screen."""

import os
import sys
import time

import bpy
import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUTPUT = os.path.join(REPO, "docs", "images", "blender-panel.png")
TAB = (1307, 762)  # the sidebar's g2p tab, window pixels from the bottom left
CROP = (430, 1300, 60, 760)  # x0, x1, top, bottom in screen pixels from the top left

sys.path[:0] = [os.environ.get("G2P_PYTHON", os.path.join(REPO, "build", "python")), os.path.join(REPO, "blender")]
import g2p_blender  # noqa: E402

started = time.time()


def view3d():
    window = bpy.context.window_manager.windows[0]
    area = next(a for a in window.screen.areas if a.type == "VIEW_3D")
    region = next(r for r in area.regions if r.type == "WINDOW")
    return window, area, region


def start():
    if bpy.context.preferences.view.show_splash:
        bpy.context.preferences.view.show_splash = False
        bpy.ops.wm.save_userpref()
        print("saved a user config without the splash screen: run again", flush=True)
        bpy.ops.wm.quit_blender()
        return None
    g2p_blender.register()
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob)
    bpy.ops.wm.obj_import(filepath=os.path.join(REPO, "examples", "data", "hammer.obj"))
    window, area, region = view3d()
    with bpy.context.temp_override(window=window, area=area, region=region, screen=window.screen):
        print("make_parts:", bpy.ops.g2p.make_parts("INVOKE_DEFAULT"), flush=True)
    bpy.app.timers.register(wait, first_interval=0.2)
    return None


def wait():
    bodies = [ob for ob in bpy.data.objects if "g2p_sources" in ob]
    if not bodies:
        if time.time() - started > 60:
            print("no result after 60 s", flush=True)
            bpy.ops.wm.quit_blender()
        return 0.2
    print(f"the run finished while the interface kept running ({time.time() - started:.1f} s)", flush=True)
    parts = [ob for ob in bodies[0].children if "g2p_class" in ob]
    bpy.ops.object.select_all(action="DESELECT")
    for ob in parts:
        ob.select_set(True)
    bpy.context.view_layer.objects.active = next(ob for ob in parts if ob["g2p_class"] == "Metal")
    window, area, region = view3d()
    area.spaces.active.show_region_ui = True
    with bpy.context.temp_override(window=window, area=area, region=region, screen=window.screen):
        bpy.ops.view3d.view_selected()
    bpy.app.timers.register(click_tab, first_interval=0.5)
    return None


def click_tab():
    window = bpy.context.window_manager.windows[0]
    window.event_simulate(type="MOUSEMOVE", value="NOTHING", x=TAB[0], y=TAB[1])
    window.event_simulate(type="LEFTMOUSE", value="PRESS", x=TAB[0], y=TAB[1])
    window.event_simulate(type="LEFTMOUSE", value="RELEASE", x=TAB[0], y=TAB[1])
    window.event_simulate(type="MOUSEMOVE", value="NOTHING", x=500, y=500)
    bpy.app.timers.register(shoot, first_interval=1.0)
    return None


def shoot():
    window, area, _ = view3d()
    full = OUTPUT + ".full.png"
    with bpy.context.temp_override(window=window, area=area, screen=window.screen):
        bpy.ops.screen.screenshot(filepath=full)
    image = bpy.data.images.load(full)
    width, height = image.size
    pixels = np.array(image.pixels[:], dtype=np.float32).reshape(height, width, 4)  # rows from the bottom
    x0, x1, top, bottom = CROP
    out = bpy.data.images.new("panel", x1 - x0, bottom - top)
    out.pixels = pixels[height - bottom:height - top, x0:x1].ravel()
    out.filepath_raw = OUTPUT
    out.file_format = "PNG"
    out.save()
    os.remove(full)
    print("wrote", OUTPUT, flush=True)
    bpy.ops.wm.quit_blender()
    return None


bpy.app.timers.register(start, first_interval=1.0)
