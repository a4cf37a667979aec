#!/usr/bin/env python3
"""Seeded mutants of real scene and glTF files through `siviflow flow` and `siviflow capture`, as a
careless or hostile asset pipeline would hand them over: JSON values replaced by extremes, by the
wrong type, or deleted, indices pushed out of range, node matrices and transforms blown up, and
the bytes of binary glTF files flipped. Every run must end with exit 0, or exit 1 and a message
naming `siviflow`; a signal, another status, a hang or a validation error fails the test, and the
mutant is kept in the work folder to replay.

usage: mutate_cli.py SIVIFLOW SOURCE_DIR WORK_DIR [--mutants N] [--seed S] [--jobs J]
                     [--env NAME=VALUE ...]
  --env sets a variable for the siviflow runs only (the GPU tests' driver, a sanitizer runtime
  to preload), not for this script.
"""
import argparse
import concurrent.futures
import copy
import json
import os
import pathlib
import random
import shutil
import subprocess
import sys

EXTREMES = [0, -1, 1e308, -1e308, 3.4e38, -3.4e38, 1e6, 1.0000001e6, 5e-324, 1e-45, 2**31, 2**32,
            2**63, -2**31, 1e30, 65535, 65536]
WRONG_TYPES = ["", "x", None, True, [], {}, [[]], [1, 2], {"a": 1}]
INDEX_KEYS = {"mesh", "node", "nodes", "accessor", "bufferView", "buffer", "indices", "POSITION",
              "NORMAL", "TEXCOORD_0", "source", "index", "material", "sampler", "texture",
              "scene", "children"}
TIMEOUT_S = 60


def paths_of(value, path=()):
    """Every place in a JSON value: (path, value) pairs, containers included."""
    yield path, value
    if isinstance(value, dict):
        for k, v in value.items():
            yield from paths_of(v, path + (k,))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from paths_of(v, path + (i,))


def set_at(doc, path, value):
    target = doc
    for p in path[:-1]:
        target = target[p]
    target[path[-1]] = value


def delete_at(doc, path):
    target = doc
    for p in path[:-1]:
        target = target[p]
    del target[path[-1]]


def mutate_json(doc, rng):
    """One to three structure-aware edits of a JSON document, in place; returns what was done."""
    done = []
    for _ in range(rng.randint(1, 3)):
        places = [(p, v) for p, v in paths_of(doc) if p]
        if not places:
            break
        path, value = rng.choice(places)
        kind = rng.random()
        if isinstance(value, (int, float)) and not isinstance(value, bool) and kind < 0.5:
            new = rng.choice(EXTREMES)
            if path[-1] in INDEX_KEYS or (len(path) > 1 and path[-2] in INDEX_KEYS):
                new = rng.choice([value + 1, value + 100, -1, 2**31, 2**32 - 1])
            set_at(doc, path, new)
            done.append(f"{'/'.join(map(str, path))} = {new}")
        elif kind < 0.7:
            new = rng.choice(WRONG_TYPES)
            set_at(doc, path, new)
            done.append(f"{'/'.join(map(str, path))} = {json.dumps(new)}")
        elif kind < 0.85:
            delete_at(doc, path)
            done.append(f"delete {'/'.join(map(str, path))}")
        elif isinstance(value, list) and value:
            value.append(copy.deepcopy(rng.choice(value)))  # a duplicate element
            done.append(f"duplicate in {'/'.join(map(str, path))}")
        else:
            set_at(doc, path, copy.deepcopy(value))
            done.append(f"keep {'/'.join(map(str, path))}")
    return done


def blow_up_transform(gltf, rng):
    """A node gets a matrix or TRS with one extreme element: finite values whose products are not."""
    nodes = gltf.get("nodes") or []
    if not nodes:
        return "no node"
    node = rng.choice(nodes)
    big = rng.choice([3.4e38, -3.4e38, 1e30, 1e20, 1e6, 5e-324, 0.0])
    if rng.random() < 0.5:
        matrix = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
        matrix[rng.randrange(16)] = big
        node.pop("translation", None), node.pop("rotation", None), node.pop("scale", None)
        node["matrix"] = matrix
        return f"node matrix element {big}"
    key = rng.choice(["translation", "scale", "rotation"])
    value = [0, 0, 0, 1] if key == "rotation" else ([1, 1, 1] if key == "scale" else [0, 0, 0])
    value[rng.randrange(len(value))] = big
    node.pop("matrix", None)
    node[key] = value
    return f"node {key} {big}"


def flip_bytes(data, rng):
    data = bytearray(data)
    for _ in range(rng.randint(1, 8)):
        i = rng.randrange(len(data))
        data[i] = rng.choice([0, 0xFF, 0x7F, 0x80, rng.randrange(256)])
    return bytes(data)


class Case:
    def __init__(self, name, folder, scene, command):
        self.name, self.folder, self.scene, self.command = name, folder, scene, command


def make_cases(source, work, count, rng):
    scenes = sorted((source / "examples" / "scenes").glob("*.json"))
    gltf_files = (sorted((source / "tests" / "fuzz" / "seeds" / "gltf").glob("*.gltf")) +
                  sorted((source / "tests" / "fuzz" / "seeds" / "gltf").glob("*.glb")) +
                  sorted((source / "examples" / "scenes" / "gltf").glob("*.gltf")))
    cases = []
    for n in range(count):
        folder = work / f"mutant_{n:04d}"
        folder.mkdir(parents=True)
        kind = n % 4
        note = ""
        if kind == 0:  # a scene file's JSON mutated; its glTF files beside it
            original = rng.choice(scenes)
            shutil.copytree(original.parent / "gltf", folder / "gltf")
            doc = json.loads(original.read_text())
            note = "; ".join(mutate_json(doc, rng))
            (folder / "scene.json").write_text(json.dumps(doc))
        else:  # a glTF file mutated, loaded as a scene's object or river
            original = rng.choice(gltf_files)
            name = original.name
            for extra in original.parent.glob("*.bin"):
                shutil.copy(extra, folder / extra.name)
            for extra in list(original.parent.glob("*.png")) + list(original.parent.glob("*.jpg")):
                shutil.copy(extra, folder / extra.name)
            if original.suffix == ".glb" or kind == 3:
                (folder / name).write_bytes(flip_bytes(original.read_bytes(), rng))
                note = f"bytes of {name}"
            else:
                gltf = json.loads(original.read_text())
                note = blow_up_transform(gltf, rng) if kind == 1 else "; ".join(mutate_json(gltf, rng))
                (folder / name).write_text(json.dumps(gltf))
            as_river = "channel" in name or "rivers" in name
            scene = {"version": 1}
            if as_river:
                scene["river"] = {"gltf": name}
            else:
                scene["river"] = {"procedural": {"length": 60.0}}
                scene["objects"] = [{"gltf": name, "translation": [0.0, 0.0, 0.0],
                                     "obstacle": rng.random() < 0.5}]
            (folder / "scene.json").write_text(json.dumps(scene))
        command = "flow" if n % 2 == 0 else "capture"
        cases.append(Case(f"mutant_{n:04d} ({command}; {original.name}: {note})", folder,
                          folder / "scene.json", command))
    return cases


SANITIZER_REPORTS = ("ERROR: AddressSanitizer", "ERROR: LeakSanitizer", "runtime error:",
                     "WARNING: ThreadSanitizer")


def run_case(siviflow, case, env):
    """(exit status, what went wrong or None)."""
    if case.command == "flow":
        args = [siviflow, "flow", str(case.scene), "--out", str(case.folder / "flow.csv")]
    else:
        out = case.folder / "frames"
        out.mkdir()
        args = [siviflow, "capture", str(case.scene), "--frames", "1", "--size", "32x18",
                "--validation", "--out", str(out)]
    try:
        done = subprocess.run(args, capture_output=True, text=True, timeout=TIMEOUT_S,
                              errors="replace", env=env)
    except subprocess.TimeoutExpired:
        return None, f"{case.name}: no answer within {TIMEOUT_S} s"
    output = done.stdout + done.stderr
    status = done.returncode
    if status < 0:
        return status, f"{case.name}: killed by signal {-status}\n{output[-2000:]}"
    if status not in (0, 1):
        return status, f"{case.name}: exit status {status}\n{output[-2000:]}"
    if status == 1 and f"siviflow {case.command}:" not in output:
        return status, f"{case.name}: exit 1 without a message\n{output[-2000:]}"
    if "validation error" in output:
        return status, f"{case.name}: a validation error\n{output[-2000:]}"
    if any(report in output for report in SANITIZER_REPORTS):
        return status, f"{case.name}: a sanitizer report\n{output[-4000:]}"
    shutil.rmtree(case.folder)  # passed: only the failures stay to replay
    return status, None


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("siviflow")
    parser.add_argument("source", type=pathlib.Path)
    parser.add_argument("work", type=pathlib.Path)
    parser.add_argument("--mutants", type=int, default=400)
    parser.add_argument("--seed", type=int, default=28)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--env", action="append", default=[])
    args = parser.parse_args()
    env = dict(os.environ)
    env.update(item.split("=", 1) for item in args.env)
    shutil.rmtree(args.work, ignore_errors=True)
    args.work.mkdir(parents=True)
    cases = make_cases(args.source, args.work, args.mutants, random.Random(args.seed))
    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        results = list(pool.map(lambda c: run_case(args.siviflow, c, env), cases))
    failures = [f for _, f in results if f]
    ran = sum(1 for status, f in results if status == 0 and not f)
    print(f"{len(cases)} mutants (seed {args.seed}): {ran} ran through (exit 0), "
          f"{len(cases) - ran - len(failures)} were refused with a message (exit 1), "
          f"{len(failures)} did neither")
    for failure in failures:
        print("FAILED " + failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
