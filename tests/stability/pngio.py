"""PNG decoding and encoding with the standard library (zlib, struct): the render rows read the
server's previews here, and their mutations write an edited image back."""
import struct
import zlib


def png_decode(data):
    """(width, height, channels, depth, rows): an 8- or 16-bit PNG (grey, RGB, grey + alpha or RGBA,
    not interlaced) inflated with zlib and its five filter types undone; rows[y][x·channels + c] in
    [0, 1]. The CRC of every chunk is checked."""
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG")
    pos, idat, ihdr = 8, [], None
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        chunk = data[pos + 8:pos + 8 + n]
        if zlib.crc32(kind + chunk) != struct.unpack(">I", data[pos + 8 + n:pos + 12 + n])[0]:
            raise ValueError(f"bad CRC in {kind!r}")
        if kind == b"IHDR":
            ihdr = struct.unpack(">IIBBBBB", chunk)
        elif kind == b"IDAT":
            idat.append(chunk)
        elif kind == b"IEND":
            break
        pos += 12 + n
    w, h, depth, ctype, _, _, interlace = ihdr
    channels = {0: 1, 2: 3, 4: 2, 6: 4}[ctype]
    if depth not in (8, 16) or interlace:
        raise ValueError(f"bit depth {depth}, interlace {interlace}: not decoded here")
    bpp = channels * depth // 8  # bytes per pixel: the filters' left neighbour
    stride = w * bpp
    raw = zlib.decompress(b"".join(idat))
    prev, rows = bytearray(stride), []
    for y in range(h):
        ftype, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if ftype == 1:
                line[i] = (line[i] + a) & 255
            elif ftype == 2:
                line[i] = (line[i] + b) & 255
            elif ftype == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif ftype == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
            elif ftype != 0:
                raise ValueError(f"filter type {ftype}")
        prev = line
        rows.append([v / 255 for v in line] if depth == 8 else [v / 65535 for v in struct.unpack(f">{stride // 2}H", line)])
    return w, h, channels, depth, rows


def png_encode(w, h, channels, depth, rows):
    """The inverse (filter 0 throughout): a mutation's edited image sent back through the check."""
    top = 255 if depth == 8 else 65535
    raw = bytearray()
    for r in rows:
        vals = [min(top, max(0, round(v * top))) for v in r]
        raw += b"\x00" + (bytes(vals) if depth == 8 else struct.pack(f">{len(vals)}H", *vals))

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    ctype = {1: 0, 3: 2, 2: 4, 4: 6}[channels]
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, depth, ctype, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(bytes(raw))) + chunk(b"IEND", b""))


def rgb_pixels(png):
    w, h, c, _, rows = png_decode(png)
    return w, h, [tuple(rows[y][x * c:x * c + 3]) for y in range(h) for x in range(w)]
