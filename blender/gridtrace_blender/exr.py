"""Reading the OpenEXR files gridtrace writes: scanline or tiled, uncompressed, RLE, ZIPS or
ZIP, 32-bit float channels — what its writer produces, read with numpy alone, since
Blender's Python offers no EXR reader for arbitrary channels.

Layout from the OpenEXR file-layout document ("The OpenEXR File Layout", openexr.com):
magic and version, a header of attributes ended by a NUL, an offset table, then chunks. RLE
and ZIP data are stored with bytes split into two halves and a difference predictor.
"""

import struct
import zlib

import numpy as np

MAGIC = 20000630
NO_COMPRESSION, RLE, ZIPS, ZIP = 0, 1, 2, 3
LINES_PER_CHUNK = {NO_COMPRESSION: 1, RLE: 1, ZIPS: 1, ZIP: 16}


class ExrError(Exception):
    """A file this reader cannot read."""


def _header(data):
    if len(data) < 8 or struct.unpack_from("<i", data, 0)[0] != MAGIC:
        raise ExrError("not an OpenEXR file")
    version = struct.unpack_from("<i", data, 4)[0]
    if version & 0x1000:  # multi-part
        raise ExrError("multi-part files are not read")
    pos, attributes = 8, {}
    while data[pos] != 0:
        name_end = data.index(b"\0", pos)
        type_end = data.index(b"\0", name_end + 1)
        (size,) = struct.unpack_from("<i", data, type_end + 1)
        start = type_end + 5
        attributes[data[pos:name_end].decode()] = (data[name_end + 1:type_end].decode(), data[start:start + size])
        pos = start + size
    return attributes, pos + 1, bool(version & 0x200)


def _channels(value):
    channels, pos = [], 0
    while value[pos] != 0:
        end = value.index(b"\0", pos)
        pixel_type, _, x_sampling, y_sampling = struct.unpack_from("<iB3xii", value, end + 1)
        if pixel_type != 2 or x_sampling != 1 or y_sampling != 1:
            raise ExrError("only full-resolution 32-bit float channels are read")
        channels.append(value[pos:end].decode())
        pos = end + 17
    return channels


def _undo_rle(data, expected):
    out = bytearray()
    pos = 0
    while pos < len(data) and len(out) < expected:
        count = struct.unpack_from("b", data, pos)[0]
        if count < 0:
            out += data[pos + 1:pos + 1 - count]
            pos += 1 - count
        else:
            out += data[pos + 1:pos + 2] * (count + 1)
            pos += 2
    return bytes(out)


def _undo_predictor_and_split(raw):
    """RLE and ZIP store the bytes with a difference predictor, the even bytes first."""
    values = np.frombuffer(raw, dtype=np.uint8).astype(np.int64)
    values[1:] -= 128
    values = np.cumsum(values) & 0xFF
    values = values.astype(np.uint8)
    half = (len(values) + 1) // 2
    out = np.empty_like(values)
    out[0::2] = values[:half]
    out[1::2] = values[half:]
    return out.tobytes()


def _decompress(compression, data, expected):
    if len(data) == expected or compression == NO_COMPRESSION:
        return data
    if compression == RLE:
        return _undo_predictor_and_split(_undo_rle(data, expected))
    if compression in (ZIPS, ZIP):
        return _undo_predictor_and_split(zlib.decompress(data))
    raise ExrError(f"compression {compression} is not read")


def read(path):
    """The channels of the EXR at `path` as {name: float32 array of shape (height, width)},
    rows from the top."""
    with open(path, "rb") as f:
        data = f.read()
    attributes, pos, tiled = _header(data)
    names = _channels(attributes["channels"][1])
    compression = attributes["compression"][1][0]
    x0, y0, x1, y1 = struct.unpack("<4i", attributes["dataWindow"][1])
    width, height = x1 - x0 + 1, y1 - y0 + 1
    planes = {name: np.zeros((height, width), dtype=np.float32) for name in names}
    if tiled:
        tile_w, tile_h, mode = struct.unpack("<IIB", attributes["tiles"][1])
        if mode & 0x0F != 0:
            raise ExrError("only single-level tiles are read")
        chunks = ((width + tile_w - 1) // tile_w) * ((height + tile_h - 1) // tile_h)
    else:
        lines = LINES_PER_CHUNK.get(compression)
        if lines is None:
            raise ExrError(f"compression {compression} is not read")
        chunks = (height + lines - 1) // lines
    offsets = struct.unpack_from(f"<{chunks}Q", data, pos)
    for offset in offsets:
        if tiled:
            tx, ty, _, _, size = struct.unpack_from("<iiiii", data, offset)
            x, y = tx * tile_w, ty * tile_h
            w, h = min(tile_w, width - x), min(tile_h, height - y)
            block = data[offset + 20:offset + 20 + size]
        else:
            line, size = struct.unpack_from("<ii", data, offset)
            x, y = 0, line - y0
            w, h = width, min(lines, height - y)
            block = data[offset + 8:offset + 8 + size]
        raw = _decompress(compression, block, w * h * 4 * len(names))
        values = np.frombuffer(raw, dtype="<f4").reshape(h, len(names), w)
        for c, name in enumerate(names):
            planes[name][y:y + h, x:x + w] = values[:, c, :]
    return planes


def text_attribute(path, name):
    """A text attribute of the header, or None."""
    with open(path, "rb") as f:
        data = f.read(1 << 20)
    attributes, _, _ = _header(data)
    kind, value = attributes.get(name, (None, None))
    return value.decode() if kind == "string" else None
