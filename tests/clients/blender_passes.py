# Blender (headless) opens a SiViFlow frame as a compositor would: an Image node, whose output
# sockets are the frame's passes, each written out through a File Output node (Blender's Viewer
# node keeps no pixels in background mode) and read back; a few pixels of each pass must carry
# the values expected (read from the frame by the test driver, clients_test.py).
#
# usage: blender -b --factory-startup --python-exit-code 1 --python blender_passes.py --
#            FRAME.exr OUT_DIR EXPECTED.json
# EXPECTED.json: {"width", "height", "passes": {name: [{"x", "y", "values": [...]}]}}, pixels
# top-down as in the EXR; Blender's images run bottom-up.
import json
import os
import sys

import bpy

frame, out_dir, expected_path = sys.argv[sys.argv.index("--") + 1:]
with open(expected_path) as f:
    expected = json.load(f)

image = bpy.data.images.load(frame)
scene = bpy.context.scene
scene.render.resolution_x, scene.render.resolution_y = expected["width"], expected["height"]
scene.render.resolution_percentage = 100
scene.use_nodes = True
tree = scene.node_tree
for node in list(tree.nodes):
    tree.nodes.remove(node)
source = tree.nodes.new("CompositorNodeImage")
source.image = image
sockets = [s.name for s in source.outputs]
print("blender_passes: sockets " + ", ".join(f"{s.name} ({s.type})" for s in source.outputs))
missing = [name for name in expected["passes"] if name not in sockets]
if missing:
    raise SystemExit(f"blender_passes: FAIL: no pass {missing} among the sockets {sockets}")

# 32-bit float RGBA EXR, one file per pass: a value pass comes back as (v, v, v, 1), a vector of
# three as (x, y, z, 1), of four as it is.
output = tree.nodes.new("CompositorNodeOutputFile")
output.base_path = out_dir
output.format.file_format = "OPEN_EXR"
output.format.color_depth = "32"
output.format.color_mode = "RGBA"
output.file_slots.clear()
for name in expected["passes"]:
    output.file_slots.new(name)
    tree.links.new(source.outputs[name], output.inputs[name])
composite = tree.nodes.new("CompositorNodeComposite")
tree.links.new(source.outputs["Combined"], composite.inputs["Image"])
scene.frame_current = 1
bpy.ops.render.render(write_still=False)

failures, compared = [], 0
for name, pixels in expected["passes"].items():
    written = bpy.data.images.load(os.path.join(out_dir, f"{name}{scene.frame_current:04d}.exr"))
    width, height = written.size
    if (width, height) != (expected["width"], expected["height"]):
        failures.append(f"{name}: written at {width}x{height}")
        continue
    data = written.pixels[:]
    for p in pixels:
        first = ((height - 1 - p["y"]) * width + p["x"]) * 4  # bottom-up rows
        got = data[first:first + len(p["values"])]
        for channel, (g, e) in enumerate(zip(got, p["values"])):
            compared += 1
            # The expected values were printed with 9 decimals (oiiotool --dumpdata): equal
            # within that and within one float32 step (2^-23 relative).
            same = g == e or abs(g - e) <= max(1e-9, abs(e) * 2.0 ** -23)
            if not same:
                failures.append(f"{name} channel {channel} at ({p['x']}, {p['y']}): "
                                f"Blender {g!r}, the frame {e!r}")
if failures:
    raise SystemExit("blender_passes: FAIL:\n" + "\n".join(failures))
print(f"blender_passes: {len(expected['passes'])} passes found, {compared} values compared "
      f"at {len(next(iter(expected['passes'].values())))} pixels, all equal")
