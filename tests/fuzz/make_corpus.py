#!/usr/bin/env python3
"""Writes the seed corpora in corpus/<target>/ (standard library only).

fuzz_frame_decode inputs are a mode byte (0 = protobuf, 1 = raw) and then
a fovea.v1.Frame, encoded here by hand from proto/fovea/v1/frame.proto's
field numbers, or FuzzedDataProvider bytes. fuzz_pcd_load inputs are PCD
files, mostly with the OSD fields label x y z rgba, in all three encodings
(binary_compressed with a small LZF compressor here). Usage:
make_corpus.py OUT_DIR (writes OUT_DIR/<target>/...); scripts/fuzz runs it
into build-fuzz/seeds, so no seed file is kept in the repository.
"""

import os
import struct
import sys
import zlib



def varint(n):
    out = bytearray()
    while True:
        byte = n & 0x7F
        n >>= 7
        if n:
            out.append(byte | 0x80)
        else:
            out.append(byte)
            return bytes(out)


def field_varint(number, value):
    return varint(number << 3) + varint(value)


def field_bytes(number, value):
    if isinstance(value, str):
        value = value.encode()
    return varint(number << 3 | 2) + varint(len(value)) + value


def field_double(number, value):
    return varint(number << 3 | 1) + struct.pack("<d", value)


def image(width=0, height=0, encoding="", step=0, data=b"", compressed=b""):
    out = b""
    if width:
        out += field_varint(1, width)
    if height:
        out += field_varint(2, height)
    if encoding:
        out += field_bytes(3, encoding)
    if step:
        out += field_varint(5, step)
    if data:
        out += field_bytes(6, data)
    if compressed:
        out += field_bytes(7, compressed)
    return out


def frame(color, depth, depth_scale=0.0):
    intrinsics = (field_double(1, 525.0) + field_double(2, 525.0) +
                  field_double(3, 1.5) + field_double(4, 1.5))
    out = field_bytes(1, color) + field_bytes(2, depth) + field_bytes(3, intrinsics)
    if depth_scale:
        out += field_double(4, depth_scale)
    return out + field_bytes(5, "camera") + field_varint(6, 1234)


def png(width, height, bit_depth, colour_type, rows):
    def chunk(kind, body):
        return (struct.pack(">I", len(body)) + kind + body +
                struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF))
    ihdr = struct.pack(">IIBBBBB", width, height, bit_depth, colour_type, 0, 0, 0)
    raw = b"".join(b"\x00" + row for row in rows)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) +
            chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


# A 4 x 4 colour JPEG (OpenCV's cv::imencode(".jpg") of pixel bytes 0, 5,
# 10, ...): there is no JPEG encoder in Python's standard library.
JPEG_4X4 = bytes.fromhex(
    "ffd8ffe000104a46494600010100000100010000ffdb0043000201010101010201010102"
    "020202020403020202020504040304060506060605060606070908060709070606080b08"
    "090a0a0a0a0a06080b0c0b0a0c090a0a0affdb004301020202020202050303050a070607"
    "0a0a0a0a0a0a0a0a0a0a0a0a0a0a0a0a0a0a0a0a0a0a0a0a0a0a0a0a0a0a0a0a0a0a0a0a"
    "0a0a0a0a0a0a0a0a0a0a0a0a0a0affc00011080004000403012200021101031101ffc400"
    "1f0000010501010101010100000000000000000102030405060708090a0bffc400b51000"
    "02010303020403050504040000017d010203000411051221314106135161072271143281"
    "91a1082342b1c11552d1f02433627282090a161718191a25262728292a3435363738393a"
    "434445464748494a535455565758595a636465666768696a737475767778797a83848586"
    "8788898a92939495969798999aa2a3a4a5a6a7a8a9aab2b3b4b5b6b7b8b9bac2c3c4c5c6"
    "c7c8c9cad2d3d4d5d6d7d8d9dae1e2e3e4e5e6e7e8e9eaf1f2f3f4f5f6f7f8f9faffc400"
    "1f0100030101010101010101010000000000000102030405060708090a0bffc400b51100"
    "020102040403040705040400010277000102031104052131061241510761711322328108"
    "144291a1b1c109233352f0156272d10a162434e125f11718191a262728292a3536373839"
    "3a434445464748494a535455565758595a636465666768696a737475767778797a828384"
    "85868788898a92939495969798999aa2a3a4a5a6a7a8a9aab2b3b4b5b6b7b8b9bac2c3c4"
    "c5c6c7c8c9cad2d3d4d5d6d7d8d9dae2e3e4e5e6e7e8e9eaf2f3f4f5f6f7f8f9faffda00"
    "0c03010002110311003f00faefe08ffc1127fe09e7ff000af2cffe2d07affcb48fd07fd3"
    "3a28a2b8cec3ffd9")


def write(target, name, data):
    folder = os.path.join(OUT, target)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, name), "wb") as f:
        f.write(data)


def frame_corpus():
    w, h = 4, 4
    rgb = bytes((17 * i) % 256 for i in range(w * h * 3))
    mm = b"".join(struct.pack("<H", 800 + 10 * i) for i in range(w * h))
    metres = b"".join(struct.pack("<f", 0.8 + 0.01 * i) for i in range(w * h))
    target = "fuzz_frame_decode"
    write(target, "raw_rgb8_16uc1", b"\x00" + frame(
        image(w, h, "rgb8", w * 3, rgb), image(w, h, "16UC1", w * 2, mm), 0.001))
    write(target, "raw_bgr8_32fc1", b"\x00" + frame(
        image(w, h, "bgr8", w * 3, rgb), image(w, h, "32FC1", w * 4, metres)))
    # Padded rows: step larger than width * bytes per pixel.
    padded = b"".join(rgb[r * 12:(r + 1) * 12] + b"\x00\x00" for r in range(h))
    write(target, "raw_padded_step", b"\x00" + frame(
        image(w, h, "rgb8", w * 3 + 2, padded), image(w, h, "16UC1", w * 2, mm)))
    colour_png = png(w, h, 8, 2, [rgb[r * 12:(r + 1) * 12] for r in range(h)])
    depth_rows = [b"".join(struct.pack(">H", 800 + 10 * (r * w + c))
                           for c in range(w)) for r in range(h)]
    depth_png = png(w, h, 16, 0, depth_rows)
    write(target, "png_pair", b"\x00" + frame(
        image(compressed=colour_png), image(compressed=depth_png)))
    write(target, "png_colour_raw_depth", b"\x00" + frame(
        image(w, h, compressed=colour_png), image(w, h, "16UC1", w * 2, mm)))
    write(target, "jpeg_colour_png_depth", b"\x00" + frame(
        image(compressed=JPEG_4X4), image(compressed=depth_png)))
    # Raw mode: FuzzedDataProvider bytes (a few arbitrary seeds).
    write(target, "direct_small", b"\x01" + bytes(range(1, 64)) * 4)
    write(target, "direct_zeros", b"\x01" + bytes(200))


PCD_HEADER = """# .PCD v0.7 - Point Cloud Data file format
VERSION 0.7
FIELDS label x y z rgba
SIZE 4 4 4 4 4
TYPE U F F F U
COUNT 1 1 1 1 1
WIDTH {width}
HEIGHT {height}
VIEWPOINT 0 0 0 1 0 0 0
POINTS {points}
DATA {kind}
"""


def lzf_compress(data):
    """Greedy LZF (liblzf's format): a back-reference to the last place each
    3-byte prefix was seen, when it is in reach, else literal runs."""
    out = bytearray()
    literal = bytearray()

    def flush():
        for start in range(0, len(literal), 32):
            chunk = literal[start:start + 32]
            out.append(len(chunk) - 1)
            out.extend(chunk)
        literal.clear()

    last = {}
    i = 0
    while i < len(data):
        key = data[i:i + 3]
        ref = last.get(key) if len(key) == 3 else None
        if len(key) == 3:
            last[key] = i
        if ref is None or i - ref > 8192:
            literal.append(data[i])
            i += 1
            continue
        length = 3
        while (length < min(264, len(data) - i) and
               data[ref + length] == data[i + length]):
            length += 1
        flush()
        distance, field = i - ref - 1, length - 2
        if field < 7:
            out.append(field << 5 | distance >> 8)
        else:
            out += bytes([7 << 5 | distance >> 8, field - 7])
        out.append(distance & 0xFF)
        i += length
    flush()
    return bytes(out)


def pcd_points():
    # A 3 x 2 organized patch 1 m away; one point has no data (NaN).
    points = []
    for v in range(2):
        for u in range(3):
            z = float("nan") if (u, v) == (2, 1) else 1.0 + 0.01 * u
            label = 1 if v == 0 else 21
            points.append((label, (u - 1) * 0.01, (v - 1) * 0.01, z,
                           (0x10 * u) << 16 | (0x20 * v) << 8 | 0x40))
    return points


def pcd_corpus():
    target = "fuzz_pcd_load"
    points = pcd_points()
    ascii_body = "".join(
        "%d %g %g %s %d\n" % (l, x, y, "nan" if z != z else "%g" % z, c)
        for l, x, y, z, c in points)
    binary_body = b"".join(struct.pack("<IfffI", *p) for p in points)
    for name, height in (("organized", 2), ("unorganized", 1)):
        width = len(points) // height
        header = lambda kind: PCD_HEADER.format(
            width=width, height=height, points=len(points), kind=kind).encode()
        write(target, name + "_ascii.pcd", header("ascii") + ascii_body.encode())
        write(target, name + "_binary.pcd", header("binary") + binary_body)
    # binary_compressed: PCL stores it field by field (structure of arrays)
    # and LZF-compresses that; a literal-only LZF stream is valid LZF.
    soa = b"".join(
        b"".join(struct.pack("<" + fmt, p[i]) for p in points)
        for i, fmt in enumerate("IfffI"))
    lzf = bytearray()
    for start in range(0, len(soa), 32):
        chunk = soa[start:start + 32]
        lzf += bytes([len(chunk) - 1]) + chunk
    header = PCD_HEADER.format(width=3, height=2, points=6,
                               kind="binary_compressed").encode()
    write(target, "organized_compressed.pcd", header +
          struct.pack("<II", len(lzf), len(soa)) + bytes(lzf))
    # A larger organized cloud, LZF with back-references (runs of equal
    # labels, colours and NaN rows).
    big = []
    for v in range(6):
        for u in range(8):
            z = float("nan") if v == 5 else 1.0 + 0.25 * (u // 4)
            big.append((0 if v == 5 else 21, 0.125 * (u - 4), 0.125 * (v - 3),
                        z, 0x404040))
    soa = b"".join(
        b"".join(struct.pack("<" + fmt, p[i]) for p in big)
        for i, fmt in enumerate("IfffI"))
    lzf = lzf_compress(soa)
    header = PCD_HEADER.format(width=8, height=6, points=len(big),
                               kind="binary_compressed").encode()
    write(target, "organized_compressed_backrefs.pcd", header +
          struct.pack("<II", len(lzf), len(soa)) + lzf)
    # COUNT > 1 and 1, 2 and 8-byte fields beside x y z; CRLF line ends.
    mixed = ("VERSION 0.7\r\nFIELDS x y z normal label intensity\r\n"
             "SIZE 4 4 4 8 2 1\r\nTYPE F F F F I U\r\nCOUNT 1 1 1 3 1 1\r\n"
             "WIDTH 2\r\nHEIGHT 1\r\nPOINTS 2\r\nDATA ascii\r\n"
             "0 0 1 0 0 1 -3 200\r\n0.01 0 1.5 nan nan nan 4 0\r\n")
    write(target, "mixed_types_crlf_ascii.pcd", mixed.encode())
    # Only x y z, float64, no label or colour.
    xyz = ("VERSION 0.7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\n"
           "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n0 0 1\n0.1 0 1.5\n")
    write(target, "xyz_float64_ascii.pcd", xyz.encode())


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: make_corpus.py OUT_DIR")
    OUT = sys.argv[1]
    frame_corpus()
    pcd_corpus()
