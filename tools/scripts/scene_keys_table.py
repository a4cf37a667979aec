#!/usr/bin/env python3
"""Prints the scene file's keys as a Markdown table (key, type, default, range, meaning), generated
from the JSON Schema so that docs/scenes.md cannot drift from what the parser takes.

usage: tools/scripts/scene_keys_table.py [--write]
  prints the table of engine/scene/scene.schema.json; --write puts it into docs/scenes.md,
  between its scene-keys markers
"""
import json
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]


def resolve(schema, node):
    """The node with its $ref merged in (the node's own keys win), recursively."""
    while "$ref" in node:
        target = schema
        for part in node["$ref"].lstrip("#/").split("/"):
            target = target[part]
        node = {**target, **{k: v for k, v in node.items() if k != "$ref"}}
    return node


def type_of(schema, node):
    if "enum" in node:
        return "one of " + ", ".join(f"`{json.dumps(v)}`" for v in node["enum"])
    if "const" in node:
        return f"`{json.dumps(node['const'])}`"
    kind = node.get("type", "")
    if kind == "array" and "items" in node:
        items = resolve(schema, node["items"])
        inner = items.get("type", "")
        if inner == "array":
            inner = "[" + resolve(schema, items["items"]).get("type", "") + ", ...]"
        count = node.get("minItems")
        if count is not None and count == node.get("maxItems"):
            return f"{count} × {inner}"
        return f"array of {inner or 'object'}"
    return kind or "object"


def range_of(schema, node):
    node = resolve(schema, node)
    if node.get("type") == "array" and "items" in node and "minimum" not in node:
        inner = range_of(schema, node["items"])
        limit = f"at most {node['maxItems']} items" if "maxItems" in node and node.get(
            "minItems") != node.get("maxItems") else ""
        return "; ".join(part for part in (inner, limit) if part)
    low = ("> " + str(node["exclusiveMinimum"])) if "exclusiveMinimum" in node else (
        ("≥ " + str(node["minimum"])) if "minimum" in node else "")
    high = ("< " + str(node["exclusiveMaximum"])) if "exclusiveMaximum" in node else (
        ("≤ " + str(node["maximum"])) if "maximum" in node else "")
    return ", ".join(part for part in (low, high) if part)


def rows(schema, node, path):
    """One row per key under `node` (an object schema), depth first, in the schema's order."""
    node = resolve(schema, node)
    for name, child in node.get("properties", {}).items():
        child = resolve(schema, child)
        key = f"{path}.{name}" if path else name
        default = json.dumps(child["default"]) if "default" in child else ""
        description = child.get("description", "").replace("|", "\\|")
        yield (f"`{key}`", type_of(schema, child), f"`{default}`" if default else "",
               range_of(schema, child), description)
        if child.get("type") == "object" or "properties" in child:
            yield from rows(schema, child, key)
        if child.get("type") == "array" and isinstance(child.get("items"), dict):
            items = resolve(schema, child["items"])
            if "properties" in items:
                yield from rows(schema, items, key + "[]")
        for variant in child.get("oneOf", []):
            yield from rows(schema, variant, key)


def table(schema):
    lines = ["| key | type | default | range | meaning |", "|---|---|---|---|---|"]
    seen = set()
    for row in rows(schema, schema, ""):
        if row[0] in seen:  # "river" and each "rivers[]" entry share the river's keys
            continue
        seen.add(row[0])
        lines.append("| " + " | ".join(row) + " |")
    return "\n".join(lines) + "\n"


BEGIN = "<!-- scene-keys:begin -->\n"
END = "<!-- scene-keys:end -->"


def main():
    text = table(json.loads((ROOT / "engine/scene/scene.schema.json").read_text()))
    if sys.argv[1:] != ["--write"]:
        sys.stdout.write(text)
        return
    doc = ROOT / "docs/scenes.md"
    before, rest = doc.read_text().split(BEGIN)
    doc.write_text(before + BEGIN + text + END + rest.split(END, 1)[1])


if __name__ == "__main__":
    main()
