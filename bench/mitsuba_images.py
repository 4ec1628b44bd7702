"""What the Mitsuba comparison scripts (`mitsuba-pbr.py`, `mitsuba-media.py`) share: reading an
EXR's RGB through Mitsuba's Bitmap, and comparing two renders of the same size (per-channel means,
and 32-px blocks off by more than 5%; blocks dark in both are left out)."""


def pixels(mi, path, width, height):
    """The image's R, G, B values, pixel after pixel."""
    bitmap = mi.Bitmap(str(path))
    channels = [bitmap.struct_()[i].name for i in range(bitmap.channel_count())]
    data = list(mi.TensorXf(bitmap).array)
    idx = [channels.index(c) for c in ("R", "G", "B")]
    n = len(channels)
    return [data[i * n + c] for i in range(width * height) for c in idx]


def compare(mi, image, reference, width, height):
    """(per channel (mean of image, mean of reference, relative difference)), blocks, blocks off."""
    a, b = pixels(mi, image, width, height), pixels(mi, reference, width, height)
    means = []
    for ch in range(3):
        ma, mb = sum(a[ch::3]) / (width * height), sum(b[ch::3]) / (width * height)
        means.append((ma, mb, ma / mb - 1))
    blocks, bad = 0, 0
    for by in range(0, height - 31, 32):
        for bx in range(0, width - 31, 32):
            sa = sb = 0.0
            for y in range(by, by + 32):
                i, j = 3 * (y * width + bx), 3 * (y * width + bx + 32)
                sa += sum(a[i:j])
                sb += sum(b[i:j])
            if sa + sb < 1e-3 * 32 * 32 * 3:
                continue  # dark in both
            blocks += 1
            bad += sb == 0 or abs(sa / sb - 1) > 0.05
    return means, blocks, bad
