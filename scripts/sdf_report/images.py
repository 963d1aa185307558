"""The image grids in the report, made small enough for one self-contained HTML page: reduced
to a fixed width (area averaging) and written as 8-bit palette PNG (stdlib zlib; numpy).

The grids are grey renders, viridis heat maps, magenta coverage marks and black labels on
white, so the palette holds 128 greys (every second level), 64 samples of viridis, magenta,
and 63 colours fitted by k-means to the pixels that none of those match (edges blended by
the reduction). A general-purpose quantizer spends its colours on the many grey pixels and
bands the heat maps' colour bar."""

import struct
import zlib

import matplotlib
import matplotlib.image as mpimg
import numpy as np

GRID_WIDTH = 900  # pixels
_GREYS = 128
_GREY_SPREAD = 6  # max - min channel (of 255) below which a pixel counts as grey
_FIXED = np.vstack([matplotlib.colormaps["viridis"](np.linspace(0.0, 1.0, 64))[:, :3] * 255.0, [[255.0, 0.0, 255.0]]])
_FITTED = 256 - _GREYS - len(_FIXED)
_MATCHED = 6.0  # distance (of 255) within which a pixel is left to a fixed colour


def _area_average(values, n_out, axis):
    """Resamples `values` to n_out samples along `axis`, each the mean of the input it covers
    (exact for piecewise-constant input: differences of the linearly interpolated running sum)."""
    values = np.moveaxis(values, axis, 0)
    n_in = values.shape[0]
    running = np.concatenate([np.zeros((1,) + values.shape[1:]), np.cumsum(values, axis=0)])
    edges = np.linspace(0.0, n_in, n_out + 1)
    index = np.minimum(np.floor(edges).astype(int), n_in - 1)
    frac = (edges - index).reshape((-1,) + (1,) * (values.ndim - 1))
    at_edges = running[index] + frac * (running[index + 1] - running[index])
    out = np.diff(at_edges, axis=0) / (n_in / n_out)
    return np.moveaxis(out, 0, axis)


def reduce_width(pixels, width):
    """`pixels`: (h, w, c) floats; returns it `width` pixels wide (aspect kept), area-averaged."""
    h, w = pixels.shape[:2]
    if w <= width:
        return pixels
    height = max(1, round(h * width / w))
    return _area_average(_area_average(pixels, height, 0), width, 1)


def _kmeans(samples, k, iterations=12, seed=1):
    rng = np.random.default_rng(seed)
    centres = samples[rng.choice(len(samples), size=min(k, len(samples)), replace=False)]
    for _ in range(iterations):
        nearest = _nearest(samples, centres)
        for i in range(len(centres)):
            members = samples[nearest == i]
            if len(members):
                centres[i] = members.mean(axis=0)
    return centres


def _nearest(samples, centres, chunk=65536):
    out = np.empty(len(samples), dtype=np.int64)
    for s in range(0, len(samples), chunk):
        part = samples[s:s + chunk]
        d = ((part[:, None, :] - centres[None, :, :]) ** 2).sum(axis=2)
        out[s:s + chunk] = d.argmin(axis=1)
    return out


def quantize(rgb8):
    """(h, w, 3) uint8 -> (indices (h, w) uint8, palette (256, 3) uint8)."""
    h, w, _ = rgb8.shape
    flat = rgb8.reshape(-1, 3).astype(np.float64)
    spread = flat.max(axis=1) - flat.min(axis=1)
    grey = spread < _GREY_SPREAD
    palette = np.zeros((256, 3))
    levels = np.round(np.linspace(0, 255, _GREYS))
    palette[:_GREYS] = levels[:, None]
    index = np.zeros(len(flat), dtype=np.int64)
    index[grey] = np.round(flat[grey].mean(axis=1) * ((_GREYS - 1) / 255.0)).astype(np.int64)
    palette[_GREYS:_GREYS + len(_FIXED)] = _FIXED
    colour = flat[~grey]
    if len(colour):
        fixed = _nearest(colour, _FIXED)
        unmatched = np.sqrt(((colour - _FIXED[fixed]) ** 2).sum(axis=1)) > _MATCHED
        centres = np.zeros((0, 3))
        if unmatched.any():
            rng = np.random.default_rng(1)
            rest = colour[unmatched]
            centres = _kmeans(rest[rng.choice(len(rest), size=min(len(rest), 20000), replace=False)].copy(), _FITTED)
            palette[_GREYS + len(_FIXED):_GREYS + len(_FIXED) + len(centres)] = centres
        everything = palette[_GREYS:_GREYS + len(_FIXED) + len(centres)]
        index[~grey] = _GREYS + _nearest(colour, everything)
    return index.reshape(h, w).astype(np.uint8), np.round(palette).astype(np.uint8)


def _chunk(tag, data):
    return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)


def palette_png(indices, palette):
    """PNG bytes of an 8-bit indexed image (every row with the 'up' filter)."""
    h, w = indices.shape
    rows = indices.astype(np.int16)
    filtered = rows.copy()
    filtered[1:] = rows[1:] - rows[:-1]
    raw = np.concatenate([np.full((h, 1), 2, np.int16), filtered & 0xFF], axis=1).astype(np.uint8).tobytes()
    return (b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 3, 0, 0, 0))
            + _chunk(b"PLTE", palette.tobytes()) + _chunk(b"IDAT", zlib.compress(raw, 9)) + _chunk(b"IEND", b""))


def write_reduced_grid(source, target, width=GRID_WIDTH):
    """Reads the PNG `source`, writes it reduced to `width` and quantized as `target`."""
    pixels = mpimg.imread(source)
    if pixels.dtype == np.uint8:
        pixels = pixels.astype(np.float64) / 255.0
    if pixels.ndim == 2:
        pixels = np.stack([pixels] * 3, axis=-1)
    pixels = reduce_width(np.asarray(pixels[..., :3], dtype=np.float64), width)
    rgb8 = np.round(np.clip(pixels, 0.0, 1.0) * 255.0).astype(np.uint8)
    indices, palette = quantize(rgb8)
    with open(target, "wb") as f:
        f.write(palette_png(indices, palette))
