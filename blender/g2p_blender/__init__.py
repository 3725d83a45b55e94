"""libg2p in Blender: the selected meshes become physical parts (one object
per material, with density, mass, centre of mass and convex hulls for
Blender's rigid body world). docs/blender.md describes it."""

bl_info = {
    "name": "g2p: physical parts",
    "author": "libg2p",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "3D Viewport > Sidebar > g2p",
    "description": "Split the selected meshes into physical parts with masses and collision hulls (libg2p)",
    "category": "Physics",
}

if "bpy" in locals():  # reloaded by Blender (F3 > Reload Scripts)
    import importlib
    from . import core, operators, ui
    for module in (core, operators, ui):
        importlib.reload(module)
else:
    from . import core, operators, ui

import bpy


def _numpy_bool_for_the_gltf_importer():
    """Blender 3.4's glTF importer (Debian 12's Blender 3.4.1) reads
    numpy.bool, an alias of bool that numpy 1.24 removed, so importing any
    GLB fails there with "module 'numpy' has no attribute 'bool'". The alias
    is put back where it is missing, and the console says so."""
    if bpy.app.version >= (3, 5, 0):
        return
    try:
        import numpy
    except ImportError:
        return
    import warnings
    with warnings.catch_warnings():  # numpy 1.24 warns that the name will come back as numpy's own scalar
        warnings.simplefilter("ignore", FutureWarning)
        missing = not hasattr(numpy, "bool")
    if missing:
        numpy.bool = bool
        print(f"g2p: numpy {numpy.__version__} lacks numpy.bool, which Blender {bpy.app.version_string}'s "
              "glTF importer uses; set numpy.bool = bool so that GLB files import")


def register():
    _numpy_bool_for_the_gltf_importer()
    for cls in operators.classes + ui.classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.g2p = bpy.props.PointerProperty(type=ui.G2P_SceneSettings)
    bpy.types.Object.g2p_correction = bpy.props.PointerProperty(type=ui.G2P_Correction)


def unregister():
    del bpy.types.Object.g2p_correction
    del bpy.types.Scene.g2p
    for cls in reversed(operators.classes + ui.classes):
        bpy.utils.unregister_class(cls)
