"""The add-on's settings, preferences and sidebar panel."""

import bpy

from . import core

ADDON = __package__
DEFAULT = "DEFAULT"  # enum item: the library's default
KEEP = "KEEP"  # enum item: no correction of this value


def module_path(context):
    prefs = context.preferences.addons.get(ADDON)
    return prefs.preferences.module_path if prefs else ""


def load_g2p(context):
    """(g2p, None) or (None, message)."""
    try:
        return core.import_g2p(bpy.path.abspath(module_path(context))), None
    except core.ModuleMissing as e:
        return None, str(e)


# Enum items built from the library must stay referenced while Blender shows them.
_segmenter_items = []
_class_items = []


def segmenter_items(self, context):
    g2p, _ = load_g2p(context)
    _segmenter_items.clear()
    if g2p is None:
        _segmenter_items.append((DEFAULT, "Library default", "the g2p module is not loaded"))
        return _segmenter_items
    defaults = core.library_defaults(g2p)
    _segmenter_items.append((DEFAULT, f"Default ({defaults['segmenter']})", "the library's default segmenter"))
    _segmenter_items.extend((n, n, f"the '{n}' segmenter") for n in defaults["segmenters"])
    return _segmenter_items


def class_items(self, context):
    g2p, _ = load_g2p(context)
    _class_items.clear()
    _class_items.append((KEEP, "Keep", "as estimated"))
    if g2p is not None:
        _class_items.extend((n, n, "") for n in g2p.MaterialTable().names)
    return _class_items


class G2P_Preferences(bpy.types.AddonPreferences):
    bl_idname = ADDON

    module_path: bpy.props.StringProperty(
        name="g2p module folder", subtype="DIR_PATH",
        description="Folder holding the g2p Python module (g2p.cpython-*.so), when Blender's Python does not "
                    "find it on its own (e.g. libg2p's build/python)")

    def draw(self, context):
        self.layout.prop(self, "module_path")
        g2p, error = load_g2p(context)
        self.layout.label(text=f"g2p {g2p.__version__} loaded" if g2p else error.split(":")[0], icon="INFO")


class G2P_SceneSettings(bpy.types.PropertyGroup):
    segmenter: bpy.props.EnumProperty(name="Segmenter", items=segmenter_items,
                                      description="How materials are told apart (--segmenter)")
    object_words: bpy.props.StringProperty(
        name="Object", description="What the object is, in words ('exercise bike'; --object); empty = identified")
    height_m: bpy.props.FloatProperty(
        name="Height", unit="LENGTH", min=0.0,
        description="The object's real height (--height); 0 = its size in the scene")
    longest_side_m: bpy.props.FloatProperty(
        name="Longest side", unit="LENGTH", min=0.0,
        description="The object's real longest side (--longest-side); 0 = its size in the scene")
    max_hulls: bpy.props.IntProperty(
        name="Hulls", min=0, soft_max=64,
        description="Most convex hulls per part; 0 = the library's default")


class G2P_Correction(bpy.types.PropertyGroup):
    """A correction being edited on a part (applied by g2p.correct)."""
    klass: bpy.props.EnumProperty(name="Class", items=class_items)
    structure: bpy.props.EnumProperty(name="Structure", items=[(KEEP, "Keep", "as estimated"), ("solid", "Solid", ""),
                                                                ("hollow", "Hollow", "")])
    density_kg_m3: bpy.props.FloatProperty(name="Density", min=0.0,
                                             description="kg/m³; 0 = keep the estimate")


class G2P_PT_panel(bpy.types.Panel):
    bl_label = "g2p: physical parts"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "g2p"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        settings = context.scene.g2p
        g2p, error = load_g2p(context)
        if g2p is None:
            layout.label(text="g2p module not found", icon="ERROR")
            layout.label(text="set its folder in the add-on's preferences")
        else:
            defaults = core.library_defaults(g2p)
            layout.prop(settings, "segmenter")
            layout.prop(settings, "object_words")
            layout.prop(settings, "height_m")
            layout.prop(settings, "longest_side_m")
            layout.prop(settings, "max_hulls")
            if settings.max_hulls == 0:
                layout.label(text=f"hull budget: the library's, {defaults['max_hulls']}")
        layout.operator("g2p.make_parts", icon="PHYSICS")

        part = context.active_object
        body = part.parent if part is not None and "g2p_class" in part else part
        if body is not None and "g2p_mass_kg" in body and "g2p_sources" in body:
            layout.label(text=f"{body['g2p_mass_kg']:.4g} kg, {body['g2p_kind']}", icon="OBJECT_DATA")
        if part is None or "g2p_class" not in part:
            return
        box = layout.box()
        box.label(text=f"part {part['g2p_part']}: {part['g2p_class']}")
        rows = [("structure", part["g2p_structure"])]
        if part["g2p_structure"] == "hollow":
            rows.append(("wall", f"{part['g2p_wall_thickness_m'] * 1000:.3g} mm"))
        rows += [("density", f"{part['g2p_density_kg_m3']:.4g} kg/m³"), ("mass", f"{part['g2p_mass_kg']:.4g} kg")]
        for label, value in rows:
            row = box.row()
            row.label(text=label)
            row.label(text=value)
        if g2p is not None:
            box.label(text="Correction")
            correction = part.g2p_correction
            box.prop(correction, "klass")
            box.prop(correction, "structure")
            box.prop(correction, "density_kg_m3", text="Density")
            box.operator("g2p.correct", icon="FILE_REFRESH")


classes = [G2P_Preferences, G2P_SceneSettings, G2P_Correction, G2P_PT_panel]

