"""Cycles' settings that both Blender comparisons (`cycles-vs-rt.py`, `cycles-layers.py`) match to
rt: the CPU device, a fixed sample count without adaptive sampling, denoising or clamping, a
1-pixel box filter, every bounce limit at rt's max depth − 1, caustics on and the "Standard" view
transform (linear output)."""


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
