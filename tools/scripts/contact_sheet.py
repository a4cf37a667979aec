#!/usr/bin/env python3
"""Renders the same frames of a scene with two or more builds of siviflow and lays them side by
side in one PNG, a row per frame and a column per build, so a reader sees at a glance whether a
change made the picture worse.

usage: tools/scripts/contact_sheet.py --out SHEET.png [--size WxH] [--frames F,F,...]
                                      [--scene SCENE.json] [--validation]
                                      NAME=BINARY NAME=BINARY ...
  Each build renders each frame with `capture --range F:F+1 --preview` (lavapipe, 2 threads, as
  CI renders); the columns come in the order given. The default scene when --scene is left out;
  --validation captures with the Khronos validation layer.
  Prints the mean and largest difference of each column against the first, per frame.
"""
import argparse
import os
import pathlib
import struct
import subprocess
import sys
import tempfile
import zlib

GAP = 4  # pixels between cells
GAP_COLOUR = bytes((40, 40, 40))
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def read_png(path):
    """(width, height, rows of RGB bytes) of an 8-bit RGB or RGBA, non-interlaced PNG."""
    data = pathlib.Path(path).read_bytes()
    if not data.startswith(PNG_SIGNATURE):
        sys.exit(f"{path}: not a PNG")
    at, idat = len(PNG_SIGNATURE), b""
    width = height = channels = 0
    while at < len(data):
        if at + 12 > len(data):
            sys.exit(f"{path}: truncated")
        length, kind = struct.unpack(">I4s", data[at:at + 8])
        body = data[at + 8:at + 8 + length]
        if len(body) != length:
            sys.exit(f"{path}: truncated in its {kind.decode('latin-1')} chunk")
        if kind == b"IEND":
            break
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            channels = {2: 3, 6: 4}.get(colour, 0)
            if depth != 8 or channels == 0 or interlace != 0:
                sys.exit(f"{path}: only 8-bit RGB or RGBA without interlace is read")
        elif kind == b"IDAT":
            idat += body
        at += 12 + length
    if channels == 0:
        sys.exit(f"{path}: no IHDR chunk")
    try:
        raw = zlib.decompress(idat)
    except zlib.error as error:
        sys.exit(f"{path}: its pixels do not inflate ({error})")
    stride = width * channels
    if len(raw) != height * (stride + 1):
        sys.exit(f"{path}: {len(raw)} bytes of pixels for {width}x{height}")
    rows, previous = [], bytearray(stride)
    for y in range(height):
        line = raw[y * (stride + 1):(y + 1) * (stride + 1)]
        if line[0] > 4:
            sys.exit(f"{path}: row {y} has filter {line[0]}; PNG has 0 to 4")
        row = unfilter(line[0], bytearray(line[1:]), previous, channels)
        rows.append(bytes(row[i] for i in range(stride) if i % channels < 3))
        previous = row
    return width, height, rows


def unfilter(kind, row, above, bpp):
    """PNG's five scanline filters undone in place (the specification's section 9)."""
    for i in range(len(row)):
        left = row[i - bpp] if i >= bpp else 0
        up = above[i]
        corner = above[i - bpp] if i >= bpp else 0
        if kind == 1:
            row[i] = (row[i] + left) & 0xFF
        elif kind == 2:
            row[i] = (row[i] + up) & 0xFF
        elif kind == 3:
            row[i] = (row[i] + (left + up) // 2) & 0xFF
        elif kind == 4:
            row[i] = (row[i] + paeth(left, up, corner)) & 0xFF
    return row


def paeth(left, up, corner):
    """Of the three neighbours, the one nearest left + up - corner (ties: left, then up)."""
    estimate = left + up - corner
    pa, pb, pc = abs(estimate - left), abs(estimate - up), abs(estimate - corner)
    return left if pa <= pb and pa <= pc else (up if pb <= pc else corner)


def write_png(path, width, rows):
    """Rows of RGB bytes, each `width` pixels, as an 8-bit RGB PNG."""
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(
            ">I", zlib.crc32(kind + body) & 0xFFFFFFFF)
    header = struct.pack(">IIBBBBB", width, len(rows), 8, 2, 0, 0, 0)
    filtered, above = [], bytes(len(rows[0]))
    for row in rows:  # Paeth (filter 4): a rendered picture packs to about half of unfiltered
        out = bytearray(b"\x04")
        for i, value in enumerate(row):
            left = row[i - 3] if i >= 3 else 0
            corner = above[i - 3] if i >= 3 else 0
            out.append((value - paeth(left, above[i], corner)) & 0xFF)
        filtered.append(bytes(out))
        above = row
    pixels = zlib.compress(b"".join(filtered), 9)
    pathlib.Path(path).write_bytes(PNG_SIGNATURE + chunk(b"IHDR", header) +
                                   chunk(b"IDAT", pixels) + chunk(b"IEND", b""))


def render(binary, args, frame, folder):
    command = [binary, "capture"] + ([args.scene] if args.scene else []) + [
        "--range", f"{frame}:{frame + 1}", "--size", args.size, "--preview", "--out", str(folder)]
    if args.validation:
        command.append("--validation")
    try:
        done = subprocess.run(command, capture_output=True, text=True)
    except OSError as error:
        sys.exit(f"{binary}: cannot run it: {error.strerror}")
    if done.returncode != 0:
        sys.exit(f"{binary} capture of frame {frame} failed:\n{done.stderr}")
    return read_png(pathlib.Path(folder) / f"frame_{frame:05d}.png")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True)
    parser.add_argument("--size", default="640x360")
    parser.add_argument("--frames", default="0,75,150")
    parser.add_argument("--scene")
    parser.add_argument("--validation", action="store_true")
    parser.add_argument("builds", nargs="+", metavar="NAME=BINARY")
    args = parser.parse_args()
    builds = [pair.split("=", 1) for pair in args.builds]
    if any(len(pair) != 2 for pair in builds):
        sys.exit("each build is NAME=BINARY")
    try:
        frames = [int(f) for f in args.frames.split(",")]
    except ValueError:
        sys.exit(f"--frames {args.frames}: not a comma list of frame numbers")
    if any(f < 0 for f in frames):
        sys.exit(f"--frames {args.frames}: a frame number is negative")
    os.environ.setdefault("VK_DRIVER_FILES", "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json")
    os.environ.setdefault("LP_NUM_THREADS", "2")

    blocks = []  # a frame's row of cells
    for frame in frames:
        cells = []
        for _, binary in builds:
            with tempfile.TemporaryDirectory() as folder:
                cells.append(render(binary, args, frame, folder))
        sizes = {(w, h) for w, h, _ in cells}
        if len(sizes) != 1:
            sys.exit(f"frame {frame}: the builds rendered different sizes: "
                     + ", ".join(f"{w}x{h}" for w, h in sorted(sizes)))
        first = cells[0][2]
        for (name, _), (_, _, rows) in zip(builds[1:], cells[1:]):
            diffs = [abs(a - b) for ra, rb in zip(first, rows) for a, b in zip(ra, rb)]
            print(f"frame {frame}: {name} against {builds[0][0]}: mean "
                  f"{sum(diffs) / len(diffs):.2f}, largest {max(diffs)} of 255")
        blocks.append([GAP_COLOUR * GAP + b"".join(rows[y] + GAP_COLOUR * GAP
                                                   for _, _, rows in cells)
                       for y in range(cells[0][1])])
    width = len(blocks[0][0]) // 3
    gap_rows = [GAP_COLOUR * width] * GAP
    sheet = gap_rows + [row for block in blocks for row in block + gap_rows]
    write_png(args.out, width, sheet)
    print(f"wrote {args.out}: {width}x{len(sheet)}, frames {args.frames} down, "
          + " | ".join(name for name, _ in builds) + " across")


if __name__ == "__main__":
    main()
