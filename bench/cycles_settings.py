"""What the Blender comparisons (`cycles-vs-rt.py`, `cycles-layers.py`, `cycles-shadow-catcher.py`) share: Cycles' settings
matched to rt (the CPU device, a fixed sample count without adaptive sampling, denoising or
clamping, a 1-pixel box filter, every bounce limit at rt's max depth − 1, caustics on and the
"Standard" view transform, linear output), their command line and the glTF export."""

import argparse
from pathlib import Path


def arguments(doc, rt_spp, out, sets=None):
    """The comparisons' command line: Cycles' and rt's sample counts and the output folder, which
    it creates. With `sets` (names), also `--set`, the first by default; `out` is then a function
    of the set's name."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--spp", type=int, default=1024)
    parser.add_argument("--rt-spp", type=int, default=rt_spp)
    parser.add_argument("--out", default=None)
    if sets:
        parser.add_argument("--set", choices=sets, default=sets[0])
    args = parser.parse_args()
    if args.out is None:
        args.out = str(out(args.set) if sets else out)
    Path(args.out).mkdir(parents=True, exist_ok=True)
    return args


def export_glb(bpy, path):
    """The scene as a .glb, with its lights and cameras, y up (as a user exports it)."""
    bpy.ops.export_scene.gltf(filepath=str(path), export_format="GLB", export_lights=True,
                              export_cameras=True, export_yup=True)


def match_rt(scene, spp, depth):
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = spp
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.pixel_filter_type = "BOX"
    scene.render.filter_size = 1.0
    c.max_bounces = depth - 1
    c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = depth - 1
    c.transparent_max_bounces = depth - 1
    c.sample_clamp_direct = c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.caustics_reflective = c.caustics_refractive = True
    c.seed = 3
    scene.view_settings.view_transform = "Standard"


def add_camera(bpy, scene, location, toward, vfov_deg):
    """A perspective camera at `location` looking along `toward` (Blender's z up), `vfov_deg`
    high, made the scene's camera (as the Blender comparisons place theirs)."""
    import math

    import mathutils  # bpy's: importable once bpy is

    bpy.ops.object.camera_add(location=location)
    cam = bpy.context.object
    cam.rotation_euler = mathutils.Vector(toward).to_track_quat("-Z", "Y").to_euler()
    cam.data.sensor_fit = "VERTICAL"
    cam.data.angle_y = math.radians(vfov_deg)
    scene.camera = cam
    return cam


def look_at(camera):
    """The camera's placement from rt's from/to/up (y up): Blender's `to_track_quat` keeps world z
    up, which is degenerate for a camera looking along z."""
    import mathutils  # bpy's: importable once bpy is

    origin = mathutils.Vector(camera["from"])
    forward = (mathutils.Vector(camera["to"]) - origin).normalized()
    right = forward.cross(mathutils.Vector(camera.get("up", [0, 1, 0]))).normalized()
    up = right.cross(forward)
    rotation = mathutils.Matrix((right, up, -forward)).transposed().to_4x4()
    return mathutils.Matrix.Translation(origin) @ rotation


def square_exr_film(scene, size):
    """A `size` x `size` image written as 32-bit linear EXR, on every core."""
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.render.threads_mode = "AUTO"
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"


def timed_render(bpy, scene, spp, out):
    """Renders `spp` samples into `out` and prints `cycles render time: SECONDS`, after a
    one-sample render that loads Cycles' kernels (which the timed render then has)."""
    import time

    scene.render.filepath = str(Path(out).resolve())
    scene.cycles.samples = 1
    bpy.ops.render.render(write_still=False)
    scene.cycles.samples = spp
    started = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    print(f"cycles render time: {time.perf_counter() - started:.3f}")


def camera_and_world(bpy, scene, camera, background):
    """rt's camera file (from, to, up, vertical fov) as the scene's camera, clipping nothing a
    bench scene holds (Blender's default far plane is 100), and a world of radiance
    `background` (rt's colour for rays that leave the scene)."""
    import math

    cam = bpy.data.cameras.new("camera")
    cam.sensor_fit = "VERTICAL"
    cam.angle_y = math.radians(camera["vfov"])
    cam.clip_start, cam.clip_end = 1e-3, 1e5
    cam_ob = bpy.data.objects.new("camera", cam)
    scene.collection.objects.link(cam_ob)
    cam_ob.matrix_world = look_at(camera)
    scene.camera = cam_ob
    world = bpy.data.worlds.new("background")
    world.use_nodes = True
    node = world.node_tree.nodes["Background"]
    node.inputs["Color"].default_value = (*background, 1.0)
    node.inputs["Strength"].default_value = 1.0
    scene.world = world


def render_with_object_index(bpy, scene, spp, depth, out, rgba=False):
    """Renders `scene` with Cycles matched to rt (`match_rt`) into a multilayer 32-bit EXR at
    `out` with the object-index pass (and alpha with `rgba`)."""
    match_rt(scene, spp, depth)
    scene.view_layers[0].use_pass_object_index = True
    settings = scene.render.image_settings
    if hasattr(settings, "media_type"):  # Blender 5: multilayer is a media type
        settings.media_type = "MULTI_LAYER_IMAGE"
    else:
        settings.file_format = "OPEN_EXR_MULTILAYER"
    settings.color_depth = "32"
    if rgba:
        settings.color_mode = "RGBA"
    scene.render.filepath = str(out)
    bpy.ops.render.render(write_still=True)


def read_channels(path):
    """Every channel of an EXR (all parts) by name, as numpy arrays (rows from the top)."""
    import OpenEXR

    out = {}
    for part in OpenEXR.File(str(path), separate_channels=True).parts:
        for name, channel in part.channels.items():
            out[name] = channel.pixels.astype("float64")
    return out
