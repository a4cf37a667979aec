#!/usr/bin/env python3
"""Writes rivers.gltf and rivers.bin beside this script: two river surfaces as SiViFlow reads them
(docs/scenes.md, "Rivers from glTF"), each a strip of quads from bank to bank, one row of vertices per
cross-section, vertex 0 on the left bank of the upstream section, the water level at y = 0.

  Bend     a river 10 m wide swinging 8 m either side of x = 0 over 120 m along +Z
  Channel  a straight channel 9 m wide along +Z at x = 40 m, beside it
  Fork     a river 12 m wide along +Z at x = -60 m, from z = -60 parting at z = 0 into two arms
           6 m wide that draw apart 0.25 m a metre each, the left one 50 m long and the right 36;
           a rectangular island 1.5 m wide and 12 m long in mid-river above the fork

Run it again after changing a number here; the committed files are its output.
"""
import json
import math
import os
import struct

SPACING = 2.0  # metres between cross-sections
ACROSS = 7     # vertices from bank to bank


def bend_centre(z):
    return 8.0 * math.sin(2.0 * math.pi * z / 120.0)


def strip(length, width, centre):
    """Positions (x, y, z) and counter-clockwise (seen from +Y) triangle indices of a strip."""
    sections = int(round(length / SPACING)) + 1
    positions = []
    for k in range(sections):
        z = -0.5 * length + k * SPACING
        # The centreline's slope turns each cross-section square to the flow.
        dz = 0.01
        slope = (centre(z + dz) - centre(z - dz)) / (2.0 * dz)
        norm = math.hypot(1.0, slope)
        across = (1.0 / norm, -slope / norm)  # unit (x, z) towards the left bank (+X)
        for j in range(ACROSS):
            offset = width * (0.5 - j / (ACROSS - 1))
            positions.append((centre(z) + offset * across[0], 0.0, z + offset * across[1]))
    indices = []
    for k in range(sections - 1):
        for j in range(ACROSS - 1):
            a = k * ACROSS + j
            b, c = a + 1, a + ACROSS
            indices += [a, b, c, b, c + 1, c]
    return positions, indices


def fork():
    """A river parting into two arms (its rows square to +Z), the island's quads left out."""
    x0, width, spread, across = -60.0, 12.0, 0.25, 8  # across: quads across each arm
    positions, indices = [], []

    def row(z, left, right, cells):
        first = len(positions)
        for j in range(cells + 1):
            positions.append((left + (right - left) * j / cells, 0.0, z))
        return list(range(first, first + cells + 1))

    def zip_rows(a, b, skip=lambda j: False):
        for j in range(len(a) - 1):
            if not skip(j):
                indices.extend([a[j], a[j + 1], b[j], a[j + 1], b[j + 1], b[j]])

    half = 0.5 * width
    rows = [row(-60.0 + SPACING * k, x0 + half, x0 - half, 2 * across) for k in range(31)]
    for k in range(30):  # the island: quads 7 and 8 across, rows 12 to 17 (z -36 to -24)
        zip_rows(rows[k], rows[k + 1], lambda j, k=k: 12 <= k < 18 and j in (7, 8))
    tip = rows[-1]
    for side, length in ((0, 50.0), (1, 36.0)):
        prev = tip[:across + 1] if side == 0 else tip[across:]
        for k in range(1, int(round(length / SPACING)) + 1):
            z = SPACING * k
            shift = spread * z * (1 if side == 0 else -1)
            left = x0 + (half if side == 0 else 0.0) + shift
            nxt = row(z, left, left - half, across)
            zip_rows(prev, nxt)
            prev = nxt
    # The island's inner vertices belong to no triangle: drop them.
    used = sorted(set(indices))
    new_index = {old: new for new, old in enumerate(used)}
    return [positions[i] for i in used], [new_index[i] for i in indices]


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    meshes = [("Bend", strip(120.0, 10.0, bend_centre)),
              ("Channel", strip(120.0, 9.0, lambda z: 40.0)),
              ("Fork", fork())]
    blob = bytearray()
    gltf = {"asset": {"version": "2.0", "generator": "examples/scenes/gltf/make_rivers.py"},
            "scene": 0, "scenes": [{"nodes": list(range(len(meshes)))}],
            "nodes": [], "meshes": [], "accessors": [], "bufferViews": []}
    for name, (positions, indices) in meshes:
        view = len(gltf["bufferViews"])
        gltf["bufferViews"].append({"buffer": 0, "byteOffset": len(blob),
                                    "byteLength": 12 * len(positions), "target": 34962})
        for p in positions:
            blob += struct.pack("<3f", *p)
        gltf["bufferViews"].append({"buffer": 0, "byteOffset": len(blob),
                                    "byteLength": 4 * len(indices), "target": 34963})
        blob += struct.pack("<%dI" % len(indices), *indices)
        rounded = [struct.unpack("<3f", struct.pack("<3f", *p)) for p in positions]
        gltf["accessors"].append({"bufferView": view, "componentType": 5126,
                                  "count": len(positions), "type": "VEC3",
                                  "min": [min(p[i] for p in rounded) for i in range(3)],
                                  "max": [max(p[i] for p in rounded) for i in range(3)]})
        gltf["accessors"].append({"bufferView": view + 1, "componentType": 5125,
                                  "count": len(indices), "type": "SCALAR"})
        gltf["meshes"].append({"name": name, "primitives": [
            {"attributes": {"POSITION": len(gltf["accessors"]) - 2},
             "indices": len(gltf["accessors"]) - 1, "mode": 4}]})
        gltf["nodes"].append({"name": name, "mesh": len(gltf["meshes"]) - 1})
    gltf["buffers"] = [{"uri": "rivers.bin", "byteLength": len(blob)}]
    with open(os.path.join(here, "rivers.bin"), "wb") as f:
        f.write(blob)
    with open(os.path.join(here, "rivers.gltf"), "w") as f:
        json.dump(gltf, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
