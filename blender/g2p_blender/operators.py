"""The operators: run the pipeline on the selected meshes (a modal operator
polling a worker thread), and rerun it with a part's correction."""

import json
import os
import shutil
import tempfile

import addon_utils
import bpy
import numpy as np

from . import core, ui

# The recent runs' results, so that a correction resumes its run (core.ResultCache).
RESULTS = core.ResultCache()


def export_glb(context, objects):
    """The objects as GLB bytes, written by Blender's own glTF exporter into a
    temporary folder the add-on removes: modifiers and world transforms applied,
    and every material channel glTF carries (base colour, metallic-roughness,
    normal, occlusion and emissive textures with their transforms, transmission,
    vertex colours), so the library reads the selection as `g2p run` reads a
    file. The selection and visibility are put back as they were."""
    if not hasattr(bpy.ops.export_scene, "gltf"):
        addon_utils.enable("io_scene_gltf2", default_set=False)
        if not hasattr(bpy.ops.export_scene, "gltf"):
            raise ValueError("Blender's glTF exporter (the io_scene_gltf2 add-on) is not available")
    layer = context.view_layer
    outside = [ob.name for ob in objects if ob.name not in layer.objects]
    if outside:
        raise ValueError("not in the current view layer, so Blender cannot export them: " + ", ".join(outside))
    selected = [ob for ob in layer.objects if ob.select_get()]
    active = layer.objects.active
    hidden = [ob for ob in objects if ob.hide_get()]
    folder = tempfile.mkdtemp(prefix="g2p-blender-")
    try:
        for ob in hidden:
            ob.hide_set(False)
        for ob in selected:
            ob.select_set(False)
        for ob in objects:
            ob.select_set(True)
        path = os.path.join(folder, "selection.glb")
        outcome = bpy.ops.export_scene.gltf(
            filepath=path, export_format="GLB", use_selection=True, export_apply=True, export_yup=True,
            export_cameras=False, export_lights=False, export_animations=False, export_extras=False,
            will_save_settings=False)
        if outcome != {"FINISHED"} or not os.path.isfile(path):
            raise ValueError(f"Blender's glTF exporter did not write the selection ({outcome})")
        with open(path, "rb") as f:
            return f.read()
    finally:
        for ob in objects:
            ob.select_set(False)
        for ob in selected:
            ob.select_set(True)
        for ob in hidden:
            ob.hide_set(True)
        layer.objects.active = active
        shutil.rmtree(folder, ignore_errors=True)


def class_material(name, colour_srgb):
    """One material per class, in the class's colour (viewport and render)."""
    material = bpy.data.materials.get("g2p " + name) or bpy.data.materials.new("g2p " + name)
    linear = [c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4 for c in colour_srgb]
    material.diffuse_color = (*linear, 1.0)
    material.use_nodes = True
    bsdf = material.node_tree.nodes.get("Principled BSDF")
    if bsdf is not None:
        bsdf.inputs["Base Color"].default_value = (*linear, 1.0)
    return material


def mesh_object(name, positions, triangles, collection):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(np.asarray(positions).tolist(), [], np.asarray(triangles).tolist())
    mesh.validate()
    ob = bpy.data.objects.new(name, mesh)
    collection.objects.link(ob)
    return ob


def add_rigid_body(context, ob, shape):
    with context.temp_override(object=ob, active_object=ob, selected_objects=[ob]):
        bpy.ops.rigidbody.object_add(type="ACTIVE")
    ob.rigid_body.collision_shape = shape
    ob.rigid_body.use_margin = True
    ob.rigid_body.collision_margin = 0.0005  # Bullet's default 4 cm would round off a small object


def build_scene(context, name, result, sources, corrections):
    """The result as a new collection: an invisible body object at the centre
    of mass carrying the rigid body (COMPOUND), one object per part (the
    closed mesh, coloured by class, with its properties), its convex hulls as
    the compound's CONVEX_HULL children, and an empty at the centre of mass.
    Returns the body object."""
    records = core.part_records(result)
    com = np.asarray(result.center_of_mass, dtype=np.float64)
    collection = bpy.data.collections.new("g2p " + name)
    context.scene.collection.children.link(collection)
    created = [collection]
    try:
        if context.scene.rigidbody_world is None:
            with context.temp_override(scene=context.scene):
                bpy.ops.rigidbody.world_add()
        body = mesh_object(name + " (g2p)", [], [], collection)
        created.append(body)
        body["g2p_collection"] = collection.name
        body["g2p_name"] = name
        body["g2p_run"] = RESULTS.put(result)  # a correction resumes this run
        body["g2p_stages"] = json.dumps([s["stage"] for s in result.stages])
        body.location = com
        body["g2p_mass_kg"] = result.mass_kg
        body["g2p_kind"] = result.kind
        body["g2p_sources"] = json.dumps(sources)
        body["g2p_corrections"] = json.dumps(corrections)
        add_rigid_body(context, body, "COMPOUND")
        body.rigid_body.mass = result.mass_kg
        friction, restitution = core.contact_settings(records)
        if friction is not None:
            body.rigid_body.friction = friction
            body.rigid_body.restitution = restitution

        centre = bpy.data.objects.new(name + " centre of mass", None)
        centre.empty_display_type = "SPHERE"
        centre.empty_display_size = 0.01
        collection.objects.link(centre)
        created.append(centre)
        centre.parent = body

        for rec in records:
            part_name = f"{name} part {rec['part']} {rec['class']}"
            part = mesh_object(part_name, rec["positions"] - com, rec["triangles"], collection)
            created.append(part)
            part.parent = body
            part.data.materials.append(class_material(rec["class"], rec["colour_srgb"]))
            part["g2p_part"] = rec["part"]
            part["g2p_class"] = rec["class"]
            part["g2p_structure"] = rec["structure"]
            part["g2p_wall_thickness_m"] = rec["wall_thickness_m"]
            part["g2p_density_kg_m3"] = rec["density_kg_m3"]
            part["g2p_mass_kg"] = rec["mass_kg"]
            part["g2p_center_of_mass"] = [float(x) for x in rec["center_of_mass"]]
            part["g2p_faces"] = [int(f) for f in rec["faces"]]  # the input faces, for corrections
            for j, (positions, triangles) in enumerate(rec["hulls"]):
                hull = mesh_object(f"{part_name} hull {j}", positions - com, triangles, collection)
                created.append(hull)
                hull.parent = body  # a compound takes its direct children's shapes
                hull.display_type = "WIRE"
                hull.hide_render = True
                add_rigid_body(context, hull, "CONVEX_HULL")
    except Exception:
        for thing in reversed(created):
            if isinstance(thing, bpy.types.Collection):
                bpy.data.collections.remove(thing)
            else:
                data = thing.data
                bpy.data.objects.remove(thing)
                if data is not None and data.users == 0:
                    bpy.data.meshes.remove(data)
        raise
    return body


def remove_result(body):
    """Removes a body object's collection and everything in it."""
    collection = bpy.data.collections.get(body.get("g2p_collection", ""))
    if collection is not None:
        for ob in list(collection.objects):
            data = ob.data
            bpy.data.objects.remove(ob)
            if isinstance(data, bpy.types.Mesh) and data.users == 0:
                bpy.data.meshes.remove(data)
        bpy.data.collections.remove(collection)


class G2P_OT_make_parts(bpy.types.Operator):
    """Split the selected meshes into physical parts (libg2p): masses, centre of mass and collision hulls"""
    bl_idname = "g2p.make_parts"
    bl_label = "Make physical parts"
    bl_options = {"REGISTER", "UNDO"}

    synchronous: bpy.props.BoolProperty(options={"HIDDEN", "SKIP_SAVE"},
                                        description="Run on the main thread (scripts, tests)")
    sources: bpy.props.StringProperty(options={"HIDDEN", "SKIP_SAVE"},
                                      description="JSON list of object names; empty = the selected meshes")
    corrections: bpy.props.StringProperty(options={"HIDDEN", "SKIP_SAVE"}, description="JSON list of corrections")
    replace: bpy.props.StringProperty(options={"HIDDEN", "SKIP_SAVE"}, description="body object to replace")

    @classmethod
    def poll(cls, context):
        return context.mode == "OBJECT"  # what is missing beyond that is reported, not greyed out

    def prepare(self, context):
        """The run, or None after reporting why not."""
        g2p, error = ui.load_g2p(context)
        if g2p is None:
            self.report({"ERROR"}, error)
            return None
        if self.sources:
            names = json.loads(self.sources)
            missing = [n for n in names if n not in bpy.data.objects]
            if missing:
                self.report({"ERROR"}, "g2p: the input objects are gone: " + ", ".join(missing))
                return None
            objects = [bpy.data.objects[n] for n in names]
        else:
            objects = [ob for ob in context.selected_objects if ob.type == "MESH"]
        if not objects:
            self.report({"ERROR"}, "g2p: select one or more mesh objects")
            return None
        self._sources = [ob.name for ob in objects]
        self._corrections = json.loads(self.corrections) if self.corrections else []
        active = context.view_layer.objects.active
        name = active.name if active in objects else objects[0].name
        settings = context.scene.g2p
        try:
            resumed = self.resume(g2p, settings)
        except (ValueError, g2p.Error) as e:
            self.report({"ERROR"}, f"g2p: {e}")
            return None
        if resumed is not None:
            return resumed
        try:
            model = g2p.load_model_from_memory(export_glb(context, objects), "glb", height_m=settings.height_m,
                                               longest_side_m=settings.longest_side_m)
            overrides = None
            if self._corrections:
                overrides = core.correction_overrides(g2p, self._corrections, g2p.MaterialTable(), model.num_faces)
            options = core.pipeline_options(g2p, "" if settings.segmenter == ui.DEFAULT else settings.segmenter, settings.object_words.strip(),
                                            settings.max_hulls, overrides)
        except (ValueError, g2p.Error) as e:
            self.report({"ERROR"}, f"g2p: {e}")
            return None
        self._name = name
        return core.Run(g2p, model, options)

    def resume(self, g2p, settings):
        """A correction of a body whose run is still held (RESULTS): that run
        resumed with the new corrections only (its own already apply), or None
        to run from the source objects. The body's name stays the run's name."""
        body = bpy.data.objects.get(self.replace) if self.replace else None
        if body is None or not self._corrections:
            return None
        previous = RESULTS.get(body.get("g2p_run", ""))
        applied = json.loads(body.get("g2p_corrections", "[]"))
        if previous is None or self._corrections[:len(applied)] != applied:
            return None
        overrides = core.correction_overrides(g2p, self._corrections[len(applied):], g2p.MaterialTable(),
                                              len(previous.face_labels))
        options = core.pipeline_options(g2p, "" if settings.segmenter == ui.DEFAULT else settings.segmenter,
                                        settings.object_words.strip(), settings.max_hulls, overrides)
        self._name = body.get("g2p_name", body.name)
        return core.Run(g2p, None, options, previous)

    def finish(self, context, run):
        """Reports the run's outcome; builds the scene only when it succeeded."""
        if run.cancelled:
            self.report({"WARNING"}, "g2p: cancelled; nothing was changed")
            return {"CANCELLED"}
        if run.error is not None:
            self.report({"ERROR"}, f"g2p run failed: {run.error}")
            return {"CANCELLED"}
        try:
            body = build_scene(context, self._name, run.result, self._sources, self._corrections)
        except Exception as e:  # nothing is left half-built (build_scene removes what it made)
            self.report({"ERROR"}, f"g2p: could not build the result in the scene: {e}")
            return {"CANCELLED"}
        if self.replace and self.replace in bpy.data.objects:
            remove_result(bpy.data.objects[self.replace])
            body.name = self.replace  # keep the name the user knew
        for name in self._sources:
            source = bpy.data.objects.get(name)
            if source is not None and source.name in context.view_layer.objects:
                source.hide_set(True)
        for ob in context.view_layer.objects:
            ob.select_set(False)
        body.select_set(True)
        context.view_layer.objects.active = body
        for w in run.result.warnings:
            self.report({"WARNING"}, f"g2p: {w}")
        resumed = f" (resumed at {run.result.stages[0]['stage']})" if run.previous is not None and run.result.stages else ""
        self.report({"INFO"}, f"g2p: {len(run.result.properties)} parts, {run.result.mass_kg:.4g} kg{resumed}")
        return {"FINISHED"}

    def execute(self, context):
        run = self.prepare(context)
        if run is None:
            return {"CANCELLED"}
        run.run()
        return self.finish(context, run)

    def invoke(self, context, event):
        if self.synchronous or bpy.app.background:
            return self.execute(context)
        self._run = self.prepare(context)
        if self._run is None:
            return {"CANCELLED"}
        self._run.start()
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.progress_begin(0, 100)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type == "ESC" and event.value == "PRESS":
            self._run.cancel()
            context.workspace.status_text_set("g2p: cancelling...")
            return {"RUNNING_MODAL"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        run = self._run
        if not run.done:
            context.workspace.status_text_set(f"g2p {run.progress:4.0%} {run.message}   (Esc cancels)")
            context.window_manager.progress_update(int(100 * run.progress))
            return {"RUNNING_MODAL"}
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        context.workspace.status_text_set(None)
        return self.finish(context, run)


class G2P_OT_correct(bpy.types.Operator):
    """Apply the correction to this part and rerun the stages after it (class: complete onwards; structure or density: properties onwards)"""
    bl_idname = "g2p.correct"
    bl_label = "Apply correction"
    bl_options = {"REGISTER", "UNDO"}

    synchronous: bpy.props.BoolProperty(options={"HIDDEN", "SKIP_SAVE"})

    @classmethod
    def poll(cls, context):
        ob = context.active_object
        return ob is not None and "g2p_faces" in ob and ob.parent is not None and "g2p_sources" in ob.parent

    def execute(self, context):
        part = context.active_object
        body = part.parent
        edit = part.g2p_correction
        correction = {"faces": list(part["g2p_faces"])}
        if edit.klass != ui.KEEP:
            correction["class"] = edit.klass
        if edit.structure != ui.KEEP:
            correction["structure"] = edit.structure
        if edit.density_kg_m3 > 0:
            correction["density_kg_m3"] = edit.density_kg_m3
        if len(correction) == 1:
            self.report({"ERROR"}, "g2p: choose a class, a structure or a density first")
            return {"CANCELLED"}
        corrections = json.loads(body["g2p_corrections"]) + [correction]
        return bpy.ops.g2p.make_parts("INVOKE_DEFAULT", synchronous=self.synchronous, sources=body["g2p_sources"],
                                      corrections=json.dumps(corrections), replace=body.name)


classes = [G2P_OT_make_parts, G2P_OT_correct]
