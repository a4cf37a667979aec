#!/usr/bin/env python3
"""The docs tier: the documentation says what the code does.

usage: check_docs.py synopsis SIVIFLOW SOURCE       README's synopsis = each command's --help usage
       check_docs.py scene-keys SOURCE              docs/scenes.md's key table = the schema's
       check_docs.py scene-example SIVIFLOW SOURCE WORK   docs/scenes.md's complete scene loads
       check_docs.py links SOURCE                   every relative link and #anchor resolves
       check_docs.py excerpts SOURCE                every <!-- excerpt: FILE --> block is FILE's
Each prints what differs and exits 1; 0 when the documentation holds.
"""
import base64
import json
import os
import pathlib
import re
import shutil
import struct
import subprocess
import sys

# The commands in the order the README's synopsis lists them.
COMMANDS = ["capture", "verify", "flow", "bench", "view", "info", "version"]
FENCE = re.compile(r"^```")


def fail(message):
    print(message)
    sys.exit(1)


def between(text, begin, end, where):
    if begin not in text or end not in text:
        fail(f"{where}: the markers {begin} and {end} are missing")
    return text.split(begin, 1)[1].split(end, 1)[0]


def fenced_blocks(lines, start):
    """The lines of the first fenced block at or after line `start`."""
    i = start
    while i < len(lines) and not FENCE.match(lines[i]):
        i += 1
    j = i + 1
    while j < len(lines) and not FENCE.match(lines[j]):
        j += 1
    if j >= len(lines):
        return None
    return lines[i + 1:j]


def usage_lines(siviflow, command):
    """The usage lines of `siviflow COMMAND --help`, without 'usage: ' and its indentation."""
    run = subprocess.run([siviflow, command, "--help"], capture_output=True, text=True, timeout=60)
    if run.returncode != 0:
        fail(f"siviflow {command} --help exited {run.returncode}: {run.stderr.strip()}")
    lines = run.stdout.splitlines()
    if not lines or not lines[0].startswith("usage: "):
        fail(f"siviflow {command} --help does not start with 'usage: ': {lines[:1]}")
    usage = [lines[0][len("usage: "):]]
    indent = " " * len("usage: ")
    for line in lines[1:]:
        if not line.startswith(indent + " "):  # continuations align under the command's name
            break
        usage.append(line[len(indent):])
    return usage


def check_synopsis(siviflow, source):
    readme = (source / "README.md").read_text()
    block = between(readme, "<!-- synopsis:begin -->", "<!-- synopsis:end -->", "README.md")
    documented = fenced_blocks(block.strip("\n").splitlines(), 0)
    if documented is None:
        fail("README.md: no fenced block between the synopsis markers")
    expected = [line for command in COMMANDS for line in usage_lines(siviflow, command)]
    if documented != expected:
        fail("README.md's synopsis differs from --help's usage lines.\nREADME:\n  " +
             "\n  ".join(documented) + "\n--help:\n  " + "\n  ".join(expected))
    print(f"synopsis: {len(expected)} lines of {len(COMMANDS)} commands agree")


def check_scene_keys(source):
    sys.path.insert(0, str(source / "tools" / "scripts"))
    import scene_keys_table  # the generator the documentation names
    expected = scene_keys_table.table(json.loads((source / "engine/scene/scene.schema.json").read_text()))
    doc = (source / "docs" / "scenes.md").read_text()
    documented = between(doc, scene_keys_table.BEGIN, scene_keys_table.END, "docs/scenes.md")
    if documented != expected:
        fail("docs/scenes.md's key table differs from the schema's; run "
             "tools/scripts/scene_keys_table.py --write")
    print(f"scene keys: {expected.count(chr(10)) - 2} keys agree with the schema")


def cube_gltf(path):
    """A 1 m cube as glTF with its buffer embedded: the stand-in for the example's props."""
    corners = [(x, y, z) for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    indices = [i for a, b, c, d in faces for i in (a, b, c, a, c, d)]
    blob = b"".join(struct.pack("<3f", *p) for p in corners) + struct.pack(f"<{len(indices)}H", *indices)
    gltf = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": 4}]}],
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 96},
                        {"buffer": 0, "byteOffset": 96, "byteLength": 2 * len(indices)}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3",
                       "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5]},
                      {"bufferView": 1, "componentType": 5123, "count": len(indices), "type": "SCALAR"}],
    }
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(gltf))


def check_scene_example(siviflow, source, work):
    lines = (source / "docs" / "scenes.md").read_text().splitlines()
    marker = [i for i, line in enumerate(lines) if line.strip() == "<!-- scene-example -->"]
    if len(marker) != 1:
        fail("docs/scenes.md: expected one <!-- scene-example --> marker")
    block = fenced_blocks(lines, marker[0] + 1)
    scene = json.loads("\n".join(block))  # a JSON error names the line
    for section in ("river", "flow", "obstacles", "objects", "camera", "render", "look"):
        if section not in scene:
            fail(f"docs/scenes.md's complete scene has no '{section}'")
    shutil.rmtree(work, ignore_errors=True)
    (work / "frames").mkdir(parents=True)
    for gltf in {entry["gltf"] for entry in scene["objects"]}:
        cube_gltf(work / gltf)
    (work / "scene.json").write_text("\n".join(block))
    run = subprocess.run([siviflow, "capture", str(work / "scene.json"), "--dry-run", "--out",
                          str(work / "frames")], capture_output=True, text=True, timeout=120)
    if run.returncode != 0:
        fail(f"docs/scenes.md's complete scene does not load: {run.stdout}{run.stderr}")
    print("scene example: loads and checks as the capture would")


def markdown_files(source):
    skip = {".git", "build", "node_modules"}
    for root, dirs, files in os.walk(source):
        dirs[:] = [d for d in dirs if d not in skip]
        for name in files:
            if name.endswith(".md"):
                yield pathlib.Path(root) / name


def anchors(path):
    """GitHub's anchors of a Markdown file's headings: lower case, punctuation dropped, spaces to -."""
    found = set()
    in_code = False
    for line in path.read_text().splitlines():
        if FENCE.match(line):
            in_code = not in_code
        match = None if in_code else re.match(r"^#{1,6}\s+(.*)$", line)
        if match:
            slug = re.sub(r"[^\w\- ]", "", match.group(1).strip().lower()).replace(" ", "-")
            found.add(slug)
    return found


def check_links(source):
    link = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")
    checked, broken = 0, []
    for path in sorted(markdown_files(source)):
        in_code = False
        for number, line in enumerate(path.read_text().splitlines(), 1):
            if FENCE.match(line):
                in_code = not in_code
            if in_code:
                continue
            for target in link.findall(re.sub(r"`[^`]*`", "", line)):
                if re.match(r"^[a-z]+:", target):  # http:, mailto: ...: not ours to check
                    continue
                checked += 1
                file_part, _, anchor = target.partition("#")
                resolved = (path.parent / file_part).resolve() if file_part else path
                where = f"{path.relative_to(source)}:{number}"
                if not resolved.exists():
                    broken.append(f"{where}: {target}: no such file")
                elif anchor and resolved.suffix == ".md" and anchor not in anchors(resolved):
                    broken.append(f"{where}: {target}: no heading makes #{anchor}")
    if broken:
        fail("broken links:\n" + "\n".join(broken))
    print(f"links: {checked} relative links resolve")


def check_excerpts(source):
    marker = re.compile(r"^<!-- excerpt: (\S+) -->$")
    count, wrong = 0, []
    for path in sorted(markdown_files(source)):
        lines = path.read_text().splitlines()
        for i, line in enumerate(lines):
            match = marker.match(line.strip())
            if not match:
                continue
            count += 1
            block = fenced_blocks(lines, i + 1)
            origin = (path.parent / match.group(1)).resolve()
            where = f"{path.relative_to(source)}:{i + 1}"
            if block is None or not origin.exists():
                wrong.append(f"{where}: no block, or no file {match.group(1)}")
                continue
            code = origin.read_text().splitlines()
            # The excerpt may be dedented as a whole: compare with each indentation the file has.
            found = any(
                [c[indent:] if c.strip() else "" for c in code[k:k + len(block)]] ==
                [b if b.strip() else "" for b in block]
                for indent in range(0, 13, 2) for k in range(len(code) - len(block) + 1)
                if all(not c.strip() or c.startswith(" " * indent) for c in code[k:k + len(block)]))
            if not found:
                wrong.append(f"{where}: the block is not a run of lines of {match.group(1)}")
    if wrong:
        fail("excerpts that are not their files':\n" + "\n".join(wrong))
    if count == 0:
        fail("no excerpt found: the guides quote no compiled code")
    print(f"excerpts: {count} blocks are runs of their files' lines")


def main():
    args = sys.argv[1:]
    checks = {
        "synopsis": (2, lambda: check_synopsis(args[1], pathlib.Path(args[2]))),
        "scene-keys": (1, lambda: check_scene_keys(pathlib.Path(args[1]))),
        "scene-example": (3, lambda: check_scene_example(args[1], pathlib.Path(args[2]),
                                                         pathlib.Path(args[3]))),
        "links": (1, lambda: check_links(pathlib.Path(args[1]).resolve())),
        "excerpts": (1, lambda: check_excerpts(pathlib.Path(args[1]).resolve())),
    }
    if not args or args[0] not in checks or len(args) != checks[args[0]][0] + 1:
        fail(__doc__)
    checks[args[0]][1]()


if __name__ == "__main__":
    main()
