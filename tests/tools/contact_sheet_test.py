#!/usr/bin/env python3
"""tools/scripts/contact_sheet.py lays each build's frames side by side: the sheet's cells are
the frames `capture --preview` writes, in the order given, two runs of one build differ by
nothing, and a build that cannot run ends it with a message and no sheet. Its PNG reader undoes
each of PNG's filters as worked out by hand here (the sheet's own writer and reader share the
Paeth predictor, so a round trip alone would not tell).

usage: contact_sheet_test.py SIVIFLOW SOURCE WORK [--env VAR=VALUE ...]   (script_main.py)
"""
import struct
import subprocess
import sys
import zlib

from script_main import run_main, test_setup

WIDTH, HEIGHT, FRAMES = 64, 36, (0, 3)


# A 2x4 RGB picture, and its scanlines filtered by hand with Sub, Up, Paeth and Average (the PNG
# specification's section 9): in row 2 Paeth predicts from above for the first pixel, and for the
# second from the corner (red) and from the left (green, blue).
PIXELS = [bytes((10, 20, 30, 15, 25, 35)), bytes((12, 22, 32, 20, 30, 40)),
          bytes((5, 5, 5, 200, 100, 50)), bytes((100, 100, 100, 50, 60, 70))]
FILTERED = [bytes((1, 10, 20, 30, 5, 5, 5)), bytes((2, 2, 2, 2, 5, 5, 5)),
            bytes((4, 249, 239, 229, 188, 95, 45)), bytes((3, 98, 98, 98, 156, 216, 251))]


def hand_filtered_png(path):
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(
            ">I", zlib.crc32(kind + body) & 0xFFFFFFFF)
    header = struct.pack(">IIBBBBB", 2, len(PIXELS), 8, 2, 0, 0, 0)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) +
                     chunk(b"IDAT", zlib.compress(b"".join(FILTERED))) + chunk(b"IEND", b""))


def main():
    siviflow, _, work, contact_sheet = test_setup("contact_sheet")

    failures = []
    hand_filtered_png(work / "filters.png")
    decoded = contact_sheet.read_png(work / "filters.png")
    if decoded != (2, len(PIXELS), PIXELS):
        failures.append(f"the hand-filtered PNG reads as {decoded}")
    sheet = work / "sheet.png"
    status, printed = run_main(contact_sheet, [
        "--out", str(sheet), "--size", f"{WIDTH}x{HEIGHT}", "--frames",
        ",".join(map(str, FRAMES)), "--validation", f"a={siviflow}", f"b={siviflow}"])
    if status != 0:
        sys.exit(f"contact_sheet.py failed ({status}):\n{printed}")
    for frame in FRAMES:
        if f"frame {frame}: b against a: mean 0.00, largest 0 of 255" not in printed:
            failures.append(f"frame {frame}: not reported identical:\n{printed}")
    width, height, rows = contact_sheet.read_png(sheet)
    gap = contact_sheet.GAP
    if (width, height) != (2 * WIDTH + 3 * gap, len(FRAMES) * (HEIGHT + gap) + gap):
        failures.append(f"sheet is {width}x{height}")
    for row_index, frame in enumerate(FRAMES):
        subprocess.run([siviflow, "capture", "--range", f"{frame}:{frame + 1}", "--size",
                        f"{WIDTH}x{HEIGHT}", "--preview", "--validation", "--out", str(work)],
                       check=True, capture_output=True)
        _, _, alone = contact_sheet.read_png(work / f"frame_{frame:05d}.png")
        top = gap + row_index * (HEIGHT + gap)
        for column in range(2):
            left = 3 * (gap + column * (WIDTH + gap))
            cell = [rows[top + y][left:left + 3 * WIDTH] for y in range(HEIGHT)]
            if cell != alone:
                failures.append(f"frame {frame}, column {column}: not the captured frame")
    missing = work / "no-such-siviflow"
    status, printed = run_main(contact_sheet, ["--out", str(work / "bad.png"), f"a={missing}"])
    if status != 1 or str(missing) not in printed:
        failures.append(f"a missing binary: exit {status}, {printed!r}")
    if (work / "bad.png").exists():
        failures.append("a failed sheet was written")
    if failures:
        sys.exit("\n".join(failures))
    print(f"sheet {width}x{height} holds each frame in each column")


if __name__ == "__main__":
    main()
