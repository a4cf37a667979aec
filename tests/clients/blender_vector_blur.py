# Blender (headless) motion-blurs a SiViFlow frame with its Vector Blur node fed by our passes:
# Image the beauty ('Combined'), Z the depth ('depth'), Speed the motion AOV ('motion', Blender's
# Vector pass layout). The sharp and the blurred beauty and the motion are written through a File
# Output node and read back, and how much of the luminance's gradient energy the blur leaves along
# four directions goes to REPORT.json: {"left": {"h", "v", "d_up", "d_down"}, "pairs"} (after /
# before; the directions in Blender's bottom-up pixels: (1, 0), (0, 1), (1, 1), (1, -1), y up).
# Only neighbours that both move at least MIN_PX pixels count: the node also softens whatever
# moves at all by about a pixel in every direction, which would drown out a short blur's direction.
#
# usage: blender -b --factory-startup --python-exit-code 1 --python blender_vector_blur.py --
#            FRAME.exr OUT_DIR REPORT.json MIN_PX
import json
import math
import os
import sys

import bpy

frame, out_dir, report_path, min_px = sys.argv[sys.argv.index("--") + 1:]
min_px = float(min_px)

image = bpy.data.images.load(frame)
scene = bpy.context.scene
scene.render.resolution_x, scene.render.resolution_y = image.size
scene.render.resolution_percentage = 100
scene.use_nodes = True
tree = scene.node_tree
for node in list(tree.nodes):
    tree.nodes.remove(node)
source = tree.nodes.new("CompositorNodeImage")
source.image = image
for name in ("Combined", "depth", "motion"):
    if name not in source.outputs:
        raise SystemExit(f"blender_vector_blur: FAIL: no pass '{name}' among "
                         f"{[s.name for s in source.outputs]}")
blur = tree.nodes.new("CompositorNodeVecBlur")
blur.factor = 1.0  # the whole motion of a frame (a 360-degree shutter)
blur.samples = 32
tree.links.new(source.outputs["Combined"], blur.inputs["Image"])
tree.links.new(source.outputs["depth"], blur.inputs["Z"])
tree.links.new(source.outputs["motion"], blur.inputs["Speed"])

output = tree.nodes.new("CompositorNodeOutputFile")
output.base_path = out_dir
output.format.file_format = "OPEN_EXR"
output.format.color_depth = "32"
output.format.color_mode = "RGBA"
output.file_slots.clear()
for name, socket in (("sharp", source.outputs["Combined"]), ("blurred", blur.outputs["Image"]),
                     ("motion", source.outputs["motion"])):
    output.file_slots.new(name)
    tree.links.new(socket, output.inputs[name])
composite = tree.nodes.new("CompositorNodeComposite")
tree.links.new(blur.outputs["Image"], composite.inputs["Image"])
scene.frame_current = 1
bpy.ops.render.render(write_still=False)


def read_back(name):
    written = bpy.data.images.load(os.path.join(out_dir, f"{name}{scene.frame_current:04d}.exr"))
    return written.size[0], written.size[1], written.pixels[:]


def luminance(pixels):
    return [0.2126 * pixels[i] + 0.7152 * pixels[i + 1] + 0.0722 * pixels[i + 2]
            for i in range(0, len(pixels), 4)]


w, h, motion = read_back("motion")
moving = [math.hypot(motion[i], motion[i + 1]) >= min_px for i in range(0, len(motion), 4)]
sharp, blurred = luminance(read_back("sharp")[2]), luminance(read_back("blurred")[2])
steps = {"h": (1, 0), "v": (0, 1), "d_up": (1, 1), "d_down": (1, -1)}
before, after, pairs = dict.fromkeys(steps, 0.0), dict.fromkeys(steps, 0.0), 0
for y in range(1, h - 1):
    for x in range(w - 1):
        here = y * w + x
        if not moving[here]:
            continue
        for name, (dx, dy) in steps.items():
            there = (y + dy) * w + x + dx
            if moving[there]:
                before[name] += (sharp[there] - sharp[here]) ** 2
                after[name] += (blurred[there] - blurred[here]) ** 2
                pairs += name == "h"
if pairs == 0 or min(before.values()) == 0.0:
    raise SystemExit(f"blender_vector_blur: FAIL: no neighbours moving {min_px} px or more")
left = {k: after[k] / before[k] for k in steps}
with open(report_path, "w") as f:
    json.dump({"before": before, "after": after, "left": left, "pairs": pairs}, f)
print(f"blender_vector_blur: {pairs} pixels moving {min_px:g} px or more; gradient energy left " +
      ", ".join(f"{k} {v:.3f}" for k, v in left.items()))
