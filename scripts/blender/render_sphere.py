"""Renders one sphere map with Blender's Cycles: the referee for rsibr's bakes (docs/blender.md).

Run with Blender's own Python (Blender 3.4 checked; --python-exit-code makes errors an exit status):

    blender -b --factory-startup --python-exit-code 1 --python scripts/blender/render_sphere.py -- \
        --env ENV.exr --bsdf lambert|ggx [--alpha A] [--colour R G B] \
        [--view X Y Z] [--size N] [--samples S] [--seed K [K ...]] --out OUT.exr

Contracts:
  * ENV is a lat-long image in the CELL-CENTRED convention that Blender's Environment Texture
    uses (texel (i, j) at longitude pi (1 - 2 (i + 0.5)/W), latitude pi/2 - pi (j + 0.5)/H), NOT
    in rsibr's (OpenEXR's) convention with texel centres on the seam and the poles, and free of
    negative texels. Make it with rsibr::to_cell_centred_latlong (core/cell_centred_latlong.h)
    from the environment rsibr bakes with (read as rsibr reads it: lossy-codec ringing folded),
    best at twice its size (less blur; docs/blender.md). An asset file handed over as shipped
    biases a Lambert sphere by ~1% under sky.exr (Cycles does not sum negative ringing as signed
    radiance); rsibr's folded map in rsibr's convention shifts a sharp highlight by half a texel.
  * Axes: rsibr's world is +Y up, Blender's +Z up; rsibr's direction (x, y, z) is Blender's
    (z, x, y), a proper rotation. With it Blender's Environment Texture shows every direction
    the radiance rsibr's lat-long convention gives it.
  * --view is rsibr's view vector v (world, toward the viewer; default 0 0 1) and the image frame
    is rsibr's world_from_view_for(v) (x right, y up, z = v; up = +Y, replaced by +Z, or +X when
    |v_z| >= 0.9, when v is parallel to it): docs/conventions.md, "View frame".
  * The ball is an exact analytic sphere of radius 1 (a point-cloud point, not a mesh) seen by an
    orthographic camera of width 2, so pixel (c, r) (row 0 at the top) is the sphere-map texel
    (c, r) of docs/conventions.md: disc coordinates x = 2 (c + 1/2)/N - 1, y = 1 - 2 (r + 1/2)/N.
    The pixel filter is 0.01 px wide: each pixel is the radiance at its centre, as rsibr's texels
    are. Pixels outside the disc have alpha 0.
  * BSDFs, both one bounce, no clamping, no denoising, no adaptive sampling:
      lambert: Diffuse BSDF, Oren-Nayar roughness 0 (Lambert), colour = albedo.
      ggx:     Glossy BSDF, distribution GGX (single scattering), no Fresnel (F = 1), colour as
               a tint. --alpha is the GGX alpha (rsibr's `roughness`); the node's Roughness is
               sqrt(alpha) since Cycles squares it. Cycles 3.x masks with the separable Smith
               G1(o) G1(i); rsibr's GgxBrdf uses the height-correlated 1/(1 + L(o) + L(i)).
  * OUT: OpenEXR, float32 RGBA, scene-linear Rec.709 (Blender's scene_linear), rows top first
    as every EXR reader shows them.
Prints one line per seed: "render_sphere: Blender V, seed K, setup S s, render R s" (wall-clock in
this process: S is the scene built in Python, R is bpy.ops.render.render, which includes Cycles'
own scene setup (BVH, the environment's importance map) and writing OUT; Blender's start-up
before the script runs is in neither).
"""

import argparse
import math
import sys
import time

import bpy
import mathutils

t_start = time.perf_counter()


def parse():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    ap = argparse.ArgumentParser(prog="render_sphere.py", description=__doc__.split("\n")[0])
    ap.add_argument("--env", required=True, help="cell-centred lat-long EXR (see the contracts above)")
    ap.add_argument("--bsdf", choices=("lambert", "ggx"), required=True)
    ap.add_argument("--alpha", type=float, default=0.5, help="GGX alpha (rsibr's roughness), in (0, 1]")
    ap.add_argument("--colour", type=float, nargs=3, default=(1.0, 1.0, 1.0), metavar=("R", "G", "B"),
                    help="Lambert albedo or GGX tint (default 1 1 1)")
    ap.add_argument("--view", type=float, nargs=3, default=(0.0, 0.0, 1.0), metavar=("X", "Y", "Z"),
                    help="rsibr view vector (world, toward the viewer)")
    ap.add_argument("--size", type=int, default=128, help="image size N (N x N)")
    ap.add_argument("--samples", type=int, default=256, help="Cycles samples per pixel")
    ap.add_argument("--seed", type=int, nargs="+", default=[0],
                    help="Cycles seed; several render one image each in this process (their OUT holds {seed})")
    ap.add_argument("--threads", type=int, default=0, help="render threads (0: all)")
    ap.add_argument("--out", required=True, help="output EXR; {seed} is replaced by the seed")
    a = ap.parse_args(argv)
    if a.bsdf == "ggx" and not (0.0 < a.alpha <= 1.0):
        ap.error("--alpha must be in (0, 1]")
    if a.size < 1 or a.samples < 1:
        ap.error("--size and --samples must be >= 1")
    if len(a.seed) > 1 and "{seed}" not in a.out:
        ap.error("--out must hold {seed} when several seeds are given")
    return a


def rsibr_view_frame(v):
    """rsibr's world_from_view_for(v): the columns x, y, z (rsibr world) of the view frame."""
    z = mathutils.Vector(v).normalized()
    up = mathutils.Vector((0.0, 1.0, 0.0))
    if up.cross(z).length_squared < 1e-20:
        up = mathutils.Vector((1.0, 0.0, 0.0)) if abs(z.z) >= 0.9 else mathutils.Vector((0.0, 0.0, 1.0))
    x = up.cross(z).normalized()
    return x, z.cross(x), z


def blender_from_rsibr(d):
    """rsibr's (x, y, z) is Blender's (z, x, y)."""
    return mathutils.Vector((d[2], d[0], d[1]))


def main():
    a = parse()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    cy = scene.cycles
    cy.device = "CPU"
    cy.samples = a.samples
    cy.use_animated_seed = False
    cy.use_denoising = False
    cy.use_adaptive_sampling = False
    cy.max_bounces = 1  # camera -> ball -> environment; the convex ball never sees itself
    cy.sample_clamp_direct = 0.0
    cy.sample_clamp_indirect = 0.0
    cy.blur_glossy = 0.0
    cy.light_sampling_threshold = 0.0
    cy.film_exposure = 1.0
    # Each pixel is sampled at its centre: a Gaussian of Cycles' smallest width (the box filter
    # ignores the width and spans the whole pixel).
    cy.pixel_filter_type = "GAUSSIAN"
    cy.filter_width = 0.01
    scene.render.resolution_x = scene.render.resolution_y = a.size
    scene.render.resolution_percentage = 100
    scene.render.pixel_aspect_x = scene.render.pixel_aspect_y = 1.0
    scene.render.film_transparent = True
    scene.render.dither_intensity = 0.0
    if a.threads > 0:
        scene.render.threads_mode = "FIXED"
        scene.render.threads = a.threads
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0

    # World: the environment, linear interpolation, importance-sampled (multiple importance).
    world = bpy.data.worlds.new("environment")
    scene.world = world
    world.use_nodes = True
    world.cycles.sampling_method = "AUTOMATIC"
    nodes = world.node_tree.nodes
    background = nodes["Background"]
    background.inputs["Strength"].default_value = 1.0
    tex = nodes.new("ShaderNodeTexEnvironment")
    tex.image = bpy.data.images.load(a.env)
    # Scene-linear Rec.709, rsibr's working space ("Linear Rec.709" from Blender 4).
    names = [item.identifier for item in tex.image.colorspace_settings.bl_rna.properties["name"].enum_items]
    tex.image.colorspace_settings.name = "Linear" if "Linear" in names else "Linear Rec.709"
    tex.interpolation = "Linear"
    tex.projection = "EQUIRECTANGULAR"
    world.node_tree.links.new(tex.outputs["Color"], background.inputs["Color"])

    # Material.
    mat = bpy.data.materials.new("ball")
    mat.use_nodes = True
    mn = mat.node_tree
    for n in list(mn.nodes):
        if n.type != "OUTPUT_MATERIAL":
            mn.nodes.remove(n)
    colour = (*a.colour, 1.0)
    if a.bsdf == "lambert":
        bsdf = mn.nodes.new("ShaderNodeBsdfDiffuse")
        bsdf.inputs["Roughness"].default_value = 0.0
    else:
        bsdf = mn.nodes.new("ShaderNodeBsdfGlossy")
        bsdf.distribution = "GGX"
        bsdf.inputs["Roughness"].default_value = math.sqrt(a.alpha)  # Cycles: alpha = roughness^2
    bsdf.inputs["Color"].default_value = colour
    mn.links.new(bsdf.outputs[0], mn.nodes["Material Output"].inputs["Surface"])

    # The ball: one vertex turned into a point of radius 1 (Cycles intersects it as a sphere).
    mesh = bpy.data.meshes.new("centre")
    mesh.from_pydata([(0.0, 0.0, 0.0)], [], [])
    ball = bpy.data.objects.new("ball", mesh)
    scene.collection.objects.link(ball)
    group = bpy.data.node_groups.new("to_sphere", "GeometryNodeTree")
    if hasattr(group, "interface"):  # Blender 4
        group.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
        group.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    else:
        group.inputs.new("NodeSocketGeometry", "Geometry")
        group.outputs.new("NodeSocketGeometry", "Geometry")
    g_in = group.nodes.new("NodeGroupInput")
    g_out = group.nodes.new("NodeGroupOutput")
    to_points = group.nodes.new("GeometryNodeMeshToPoints")
    to_points.inputs["Radius"].default_value = 1.0
    set_mat = group.nodes.new("GeometryNodeSetMaterial")
    set_mat.inputs["Material"].default_value = mat
    group.links.new(g_in.outputs[0], to_points.inputs["Mesh"])
    group.links.new(to_points.outputs[0], set_mat.inputs["Geometry"])
    group.links.new(set_mat.outputs[0], g_out.inputs[0])
    ball.modifiers.new("to_sphere", "NODES").node_group = group

    # Camera: orthographic, width 2, on the view axis looking at the centre; its local x, y, z
    # are the view frame's x (right), y (up) and z (toward the viewer).
    cam = bpy.data.cameras.new("view")
    cam.type = "ORTHO"
    cam.ortho_scale = 2.0
    cam.sensor_fit = "HORIZONTAL"
    cam.clip_start = 0.1
    cam.clip_end = 100.0
    cam_obj = bpy.data.objects.new("view", cam)
    scene.collection.objects.link(cam_obj)
    scene.camera = cam_obj
    x, y, z = (blender_from_rsibr(c) for c in rsibr_view_frame(a.view))
    distance = 10.0
    m = mathutils.Matrix.Identity(4)
    for row in range(3):
        m[row][0], m[row][1], m[row][2], m[row][3] = x[row], y[row], z[row], distance * z[row]
    cam_obj.matrix_world = m

    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR"
    settings.color_depth = "32"
    settings.color_mode = "RGBA"
    settings.exr_codec = "ZIP"
    scene.render.use_file_extension = False

    # Each render rebuilds Cycles' scene (BVH, the environment's importance map: ~1.5 s); only
    # Blender's start-up (~1.4 s) is shared between seeds.
    setup = time.perf_counter() - t_start
    for seed in a.seed:
        cy.seed = seed
        scene.render.filepath = a.out.replace("{seed}", str(seed))
        t_render = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        print("render_sphere: Blender %s, seed %d, setup %.2f s, render %.2f s (Cycles' scene setup included)"
              % (bpy.app.version_string, seed, setup, time.perf_counter() - t_render), flush=True)


main()
