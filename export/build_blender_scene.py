# Builds a Blender scene from the scene.json that `rsibr export blender` writes beside this script,
# and saves it as a .blend (and, on request, renders one view). Run by Blender's own Python:
#
#   blender -b --factory-startup --python build_blender_scene.py -- --scene scene.json --blend scene.blend
#   blender -b scene.blend --python build_blender_scene.py -- --render 1 --image view00.exr
#
# Contract of scene.json (written by rsibr, export/blender_scene.h): every position, direction and
# rotation is already in Blender's +Z-up world (rsibr's (x, y, z) is Blender's (z, x, y)); lengths
# in metres; the world image is an equirectangular EXR in Blender's cell-centred convention; the
# photos, when there are any, are scene-linear radiance (a run's merged views, undistorted to the
# cameras' pinholes). Frame i (1-based) of the timeline shows camera i (over photo i).
import argparse
import json
import os
import sys

import bpy
import mathutils


def arguments():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="build_blender_scene.py")
    p.add_argument("--scene", help="scene.json written by rsibr export blender (builds the scene)")
    p.add_argument("--blend", help="save the built scene here (.blend)")
    p.add_argument("--render", type=int, help="render this frame (1-based view number)")
    p.add_argument("--image", help="the rendered image (.exr: linear RGBA, .png: the composite over the photo)")
    p.add_argument("--samples", type=int, help="Cycles samples per pixel for --render")
    p.add_argument("--seed", type=int, default=0, help="Cycles seed for --render")
    p.add_argument("--alpha-of", help="--render shows only this ball, on a transparent film (its coverage)")
    return p.parse_args(argv)


def fail(message):
    print("build_blender_scene.py: " + message, file=sys.stderr)
    sys.exit(2)


def load_image(folder, name, colour_space):
    image = bpy.data.images.load(os.path.join(folder, name), check_existing=True)
    image.colorspace_settings.name = colour_space
    image.filepath = "//" + name  # relative to the .blend, which is saved in the same folder
    return image


def world_node_tree(scene, image):
    world = bpy.data.worlds.new("rsibr probe")
    scene.world = world
    world.use_nodes = True
    nodes = world.node_tree.nodes
    texture = nodes.new("ShaderNodeTexEnvironment")
    texture.image = image
    texture.interpolation = "Linear"
    texture.projection = "EQUIRECTANGULAR"
    world.node_tree.links.new(texture.outputs["Color"], nodes["Background"].inputs["Color"])
    return world


def clear_material(name):
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    nodes = material.node_tree.nodes
    for node in list(nodes):
        if node.type != "OUTPUT_MATERIAL":
            nodes.remove(node)
    return material, nodes, material.node_tree.links


def diffuse_material(ball):
    # Lambert: Cycles' Diffuse BSDF at roughness 0.
    material, nodes, links = clear_material(ball["name"])
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (*ball["colour"], 1.0)
    diffuse.inputs["Roughness"].default_value = 0.0
    links.new(diffuse.outputs["BSDF"], nodes["Material Output"].inputs["Surface"])
    return material


def glossy_material(ball, folder):
    # Cycles' Glossy BSDF (Fresnel 1): sharp at roughness 0, else GGX with roughness sqrt(alpha).
    # A Fresnel table tints it by F(cos) of the angle between the normal and the viewer, looked up
    # in a table rsibr wrote (texel k holds F at cos = (k + 0.5) / N): exact for a mirror, the
    # usual approximation of F at the half vector for a rough lobe.
    material, nodes, links = clear_material(ball["name"])
    glossy = nodes.new("ShaderNodeBsdfGlossy")
    roughness = ball["roughness"]
    glossy.distribution = "SHARP" if roughness == 0 else "GGX"
    glossy.inputs["Roughness"].default_value = roughness
    glossy.inputs["Color"].default_value = (*ball["colour"], 1.0)
    if ball.get("fresnel_table"):
        geometry = nodes.new("ShaderNodeNewGeometry")
        dot = nodes.new("ShaderNodeVectorMath")
        dot.operation = "DOT_PRODUCT"
        links.new(geometry.outputs["Normal"], dot.inputs[0])
        links.new(geometry.outputs["Incoming"], dot.inputs[1])
        absolute = nodes.new("ShaderNodeMath")
        absolute.operation = "ABSOLUTE"
        links.new(dot.outputs["Value"], absolute.inputs[0])
        uv = nodes.new("ShaderNodeCombineXYZ")
        links.new(absolute.outputs["Value"], uv.inputs["X"])
        uv.inputs["Y"].default_value = 0.5
        table = nodes.new("ShaderNodeTexImage")
        table.image = load_image(folder, ball["fresnel_table"], "Non-Color")
        table.extension = "EXTEND"
        table.interpolation = "Linear"
        links.new(uv.outputs["Vector"], table.inputs["Vector"])
        tint = nodes.new("ShaderNodeMixRGB")
        tint.blend_type = "MULTIPLY"
        tint.inputs["Fac"].default_value = 1.0
        tint.inputs["Color1"].default_value = (*ball["colour"], 1.0)
        links.new(table.outputs["Color"], tint.inputs["Color2"])
        links.new(tint.outputs["Color"], glossy.inputs["Color"])
    links.new(glossy.outputs["BSDF"], nodes["Material Output"].inputs["Surface"])
    return material


def exact_sphere(obj, radius, material):
    # One point of a point cloud, which Cycles intersects as an exact sphere (geometry nodes: the
    # object's single vertex to a point of this radius, with the material).
    tree = bpy.data.node_groups.new(obj.name + " sphere", "GeometryNodeTree")
    tree.inputs.new("NodeSocketGeometry", "Geometry")
    tree.outputs.new("NodeSocketGeometry", "Geometry")
    given = tree.nodes.new("NodeGroupInput")
    result = tree.nodes.new("NodeGroupOutput")
    points = tree.nodes.new("GeometryNodeMeshToPoints")
    points.inputs["Radius"].default_value = radius
    set_material = tree.nodes.new("GeometryNodeSetMaterial")
    set_material.inputs["Material"].default_value = material
    tree.links.new(given.outputs[0], points.inputs["Mesh"])
    tree.links.new(points.outputs["Points"], set_material.inputs["Geometry"])
    tree.links.new(set_material.outputs["Geometry"], result.inputs[0])
    obj.modifiers.new("sphere", "NODES").node_group = tree


def add_ball(scene, ball, folder):
    mesh = bpy.data.meshes.new(ball["name"])
    obj = bpy.data.objects.new(ball["name"], mesh)
    scene.collection.objects.link(obj)
    material = diffuse_material(ball) if ball["material"] == "diffuse" else glossy_material(ball, folder)
    if ball.get("geometry") == "exact":
        mesh.from_pydata([(0.0, 0.0, 0.0)], [], [])
        exact_sphere(obj, ball["radius"], material)
    else:
        # A fine UV sphere, smooth shaded (editable, seen in every viewport): within about 1e-4 rad
        # of the true sphere's normals except in the last few percent of the radius seen edge-on.
        import bmesh

        bm = bmesh.new()
        bmesh.ops.create_uvsphere(bm, u_segments=128, v_segments=64, radius=ball["radius"])
        bm.to_mesh(mesh)
        bm.free()
        for polygon in mesh.polygons:
            polygon.use_smooth = True
    mesh.materials.append(material)
    obj.location = ball["centre"]
    obj["rsibr_kind"] = ball["kind"]
    return obj


def add_camera(scene, view, index):
    data = bpy.data.cameras.new(view["name"])
    obj = bpy.data.objects.new(view["name"], data)
    scene.collection.objects.link(obj)
    rotation = mathutils.Matrix(view["rotation"])
    obj.matrix_world = mathutils.Matrix.Translation(view["location"]) @ rotation.to_4x4()
    data.clip_start, data.clip_end = view["clip"]
    if view.get("orthographic_width"):
        # A sphere map's view: orthographic, the image as wide as the ball.
        data.type = "ORTHO"
        data.ortho_scale = view["orthographic_width"]
    else:
        width, height = view["size"]
        fx, fy = view["focal_px"]
        cx, cy = view["principal_px"]
        # Pinhole from the intrinsics (pixels, mrcal's convention: (0, 0) is the top-left pixel's
        # centre). Horizontal fit with fx; the other focal length through the pixel aspect.
        data.sensor_fit = "HORIZONTAL"
        data.sensor_width = 36.0
        data.lens = fx * data.sensor_width / width
        larger = max(width, height)
        data.shift_x = ((width - 1) / 2 - cx) / larger
        data.shift_y = (cy - (height - 1) / 2) / larger
    marker = scene.timeline_markers.new(view["name"], frame=index + 1)
    marker.camera = obj
    return obj


def compositor(scene, folder, photos):
    # Frame i: the render over photo i (the photos are an image sequence photos/photo_0001.exr ...).
    scene.use_nodes = True
    tree = scene.node_tree
    for node in list(tree.nodes):
        tree.nodes.remove(node)
    layers = tree.nodes.new("CompositorNodeRLayers")
    photo = tree.nodes.new("CompositorNodeImage")
    photo.image = load_image(folder, photos[0], "Linear")
    photo.image.source = "SEQUENCE"
    photo.frame_duration = len(photos)
    photo.frame_start = 1
    photo.use_auto_refresh = True
    over = tree.nodes.new("CompositorNodeAlphaOver")
    tree.links.new(photo.outputs["Image"], over.inputs[1])
    tree.links.new(layers.outputs["Image"], over.inputs[2])
    out = tree.nodes.new("CompositorNodeComposite")
    tree.links.new(over.outputs["Image"], out.inputs["Image"])


def build(scene_file):
    folder = os.path.dirname(os.path.abspath(scene_file))
    with open(scene_file) as f:
        spec = json.load(f)
    if spec.get("rsibr_blender_scene") != 1:
        fail(scene_file + ": not an rsibr Blender scene (version 1)")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.name = "rsibr"
    scene.unit_settings.system = "METRIC"
    scene.render.engine = "CYCLES"
    scene.cycles.samples = spec["samples"]
    scene.cycles.use_denoising = False
    # No clamping: the run's radiance is in its own units (often thousands), and Cycles' default
    # indirect clamp of 10 would blacken every reflection of one ball in another.
    scene.cycles.sample_clamp_direct = 0.0
    scene.cycles.sample_clamp_indirect = 0.0
    scene.render.film_transparent = True
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.exposure = spec["display"]["exposure_stops"]
    width, height = spec["cameras"][0]["size"]
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    if "focal_px" in spec["cameras"][0]:
        fx, fy = spec["cameras"][0]["focal_px"]
        scene.render.pixel_aspect_x, scene.render.pixel_aspect_y = 1.0, max(1.0, fx / fy)
    if spec.get("pixel_filter") == "centre":
        # Each pixel the radiance at its centre, as a sphere map's texel is (Cycles' Box filter
        # averages the whole pixel whatever its width; a 0.01 px Gaussian samples the centre).
        scene.cycles.filter_width = 0.01
        scene.cycles.pixel_filter_type = "GAUSSIAN"
    world_node_tree(scene, load_image(folder, spec["world"]["image"], "Linear"))
    for ball in spec["balls"]:
        add_ball(scene, ball, folder)
    cameras = [add_camera(scene, view, i) for i, view in enumerate(spec["cameras"])]
    photos = [view.get("photo") for view in spec["cameras"]]
    for cam, photo in zip(cameras, photos):
        if photo:
            background = cam.data.background_images.new()
            background.image = load_image(folder, photo, "Linear")
            cam.data.show_background_images = True
    scene.camera = cameras[0]
    scene.frame_start, scene.frame_end = 1, len(cameras)
    if all(photos):
        compositor(scene, folder, photos)
    else:
        scene.render.film_transparent = False
    return scene


def render(scene, args):
    if not args.image:
        fail("--render needs --image")
    if not 1 <= args.render <= scene.frame_end:
        fail("--render %d: the scene has frames 1 to %d" % (args.render, scene.frame_end))
    scene.frame_set(args.render)
    scene.camera = next(m.camera for m in scene.timeline_markers if m.frame == args.render)
    if args.samples:
        scene.cycles.samples = args.samples
    scene.cycles.seed = args.seed
    scene.cycles.use_adaptive_sampling = False
    exr = args.image.lower().endswith(".exr")
    if args.alpha_of:
        kept = [o for o in scene.objects if o.name == args.alpha_of]
        if not kept:
            fail("--alpha-of %s: no such ball" % args.alpha_of)
        for obj in scene.objects:
            if obj.type == "MESH" and obj.name != args.alpha_of:
                obj.hide_render = True
    # EXR: the linear render itself (world visible, no compositing); PNG: the composite, displayed.
    scene.render.film_transparent = bool(args.alpha_of) or (not exr and scene.use_nodes)
    scene.render.use_compositing = not exr and scene.use_nodes
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR" if exr else "PNG"
    settings.color_mode = "RGBA"
    if exr:
        settings.color_depth = "32"
    scene.render.filepath = os.path.abspath(args.image)
    bpy.ops.render.render(write_still=True)


def main():
    args = arguments()
    if args.scene:
        scene = build(args.scene)
        if args.blend:
            bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(args.blend), relative_remap=True)
    else:
        scene = bpy.context.scene
        if scene.name != "rsibr":
            fail("give --scene scene.json, or open a .blend that rsibr exported")
    if args.render is not None:
        render(scene, args)


main()
