"""The operators: run the pipeline on the selected meshes (a modal operator
polling a worker thread), and rerun it with a part's correction."""

import json

import bpy
import numpy as np

from . import core, ui


def gather(context, objects, name):
    """The objects' evaluated geometry (modifiers applied, world transform
    applied, triangulated) and material slots as a core.MeshInput."""
    depsgraph = context.evaluated_depsgraph_get()
    data = core.MeshInput(name)
    for ob in objects:
        ob_eval = ob.evaluated_get(depsgraph)
        mesh = ob_eval.to_mesh()
        try:
            mesh.calc_loop_triangles()
            positions = np.empty(len(mesh.vertices) * 3, dtype=np.float64)
            mesh.vertices.foreach_get("co", positions)
            triangles = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
            mesh.loop_triangles.foreach_get("vertices", triangles)
            slots = np.empty(len(mesh.loop_triangles), dtype=np.int32)
            mesh.loop_triangles.foreach_get("material_index", slots)
            corner_uvs = None
            if mesh.uv_layers.active is not None and any(textured(s.material) for s in ob.material_slots):
                loops = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
                mesh.loop_triangles.foreach_get("loops", loops)
                loop_uvs = np.empty(len(mesh.loops) * 2, dtype=np.float64)
                mesh.uv_layers.active.data.foreach_get("uv", loop_uvs)
                corner_uvs = loop_uvs.reshape(-1, 2)[loops]
        finally:
            ob_eval.to_mesh_clear()
        matrix = np.array(ob.matrix_world, dtype=np.float64)
        positions = positions.reshape(-1, 3) @ matrix[:3, :3].T + matrix[:3, 3]
        triangles = triangles.reshape(-1, 3)
        uvs = None
        if corner_uvs is not None:
            source, triangles, uvs = core.split_by_uv(triangles, corner_uvs)
            positions = positions[source]
        if np.linalg.det(matrix[:3, :3]) < 0:  # a mirroring transform turns the faces inside out
            triangles = triangles[:, ::-1]
        materials = [(s.material.name_full, material_record(s.material)) if s.material else None
                     for s in ob.material_slots]
        data.add(positions, triangles, materials, slots, uvs)
    return data


def principled(material):
    if material is None or not material.use_nodes or material.node_tree is None:
        return None
    return next((n for n in material.node_tree.nodes if n.type == "BSDF_PRINCIPLED"), None)


def base_color_image(material):
    """The image node feeding the Principled base colour directly, if any."""
    bsdf = principled(material)
    if bsdf is None or not bsdf.inputs["Base Color"].is_linked:
        return None
    node = bsdf.inputs["Base Color"].links[0].from_node
    return node.image if node.type == "TEX_IMAGE" else None


def image_bytes(image):
    """(bytes, MIME type) of a PNG or JPEG image as packed or on disk, or None:
    other images are not re-encoded (cheap only)."""
    mime = {"PNG": "image/png", "JPEG": "image/jpeg"}.get(image.file_format)
    if mime is None:
        return None
    if image.packed_file is not None:
        return bytes(image.packed_file.data), mime
    path = bpy.path.abspath(image.filepath)
    try:
        with open(path, "rb") as f:
            return f.read(), mime
    except OSError:
        return None


def textured(material):
    image = base_color_image(material)
    return image is not None and image_bytes(image) is not None


def material_record(material):
    """A material's name and look, as glTF would carry them (linear base colour)."""
    record = {"name": material.name, "base_color": tuple(material.diffuse_color)}
    bsdf = principled(material)
    if bsdf is not None:
        record["base_color"] = tuple(bsdf.inputs["Base Color"].default_value)
        for key, socket in (("metallic", "Metallic"), ("roughness", "Roughness")):
            if not bsdf.inputs[socket].is_linked:  # a texture drives it otherwise: glTF's default factor, 1
                record[key] = bsdf.inputs[socket].default_value
        image = base_color_image(material)
        if image is not None and image_bytes(image) is not None:
            record["base_color_image"] = image_bytes(image)
            record["base_color"] = (1.0, 1.0, 1.0, 1.0)  # the input's factor is not recovered; glTF's default
    return record


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
            data = gather(context, objects, name)
            model = data.model(g2p)
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
        self.report({"INFO"}, f"g2p: {len(run.result.properties)} parts, {run.result.mass_kg:.4g} kg")
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
