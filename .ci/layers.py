#!/usr/bin/env python3
"""Fails when a module of the crate imports from a layer above its own, or when the files
of one module import each other in a circle (docs/architecture.md, "Layers").

The layer table below is the one truth of the crate's layering: a module may use only
modules of a strictly lower layer. Imports are read as text (`crate::name` anywhere in a
file's code, comments stripped; `super::sibling::` inside a module's own files), which is how the crate spells every one of them.
"""
import os
import re
import sys

# Bottom to top. A module may import only from rows above its own.
LAYERS = [
    ["format"],
    ["error"],
    ["cost", "statistics"],
    ["files"],
    ["geometry", "lock"],
    ["green", "surface"],
    ["interface"],
    ["contact"],
    ["solver"],
    ["probe"],
    ["recording"],
    ["scene"],
    ["driver"],
    ["avalanche"],
    ["calibration", "output", "matrix"],
    ["sweep"],
    ["plot"],
]
RANK = {name: rank for rank, row in enumerate(LAYERS) for name in row}


def code(path):
    """The file's text without comments, string and char literals (one pass, so a `//`
    inside a string or a quote inside a comment cannot confuse it)."""
    text = open(path, encoding="utf-8").read()
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            i = text.find("\n", i)
            i = n if i < 0 else i
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            i = n if j < 0 else j + 2
        elif c == "r" and re.match(r'r#*"', text[i:]) and not (i and (text[i - 1].isalnum() or text[i - 1] == "_")):
            hashes = re.match(r'r(#*)"', text[i:]).group(1)
            j = text.find('"' + hashes, i + len(hashes) + 2)
            i = n if j < 0 else j + 1 + len(hashes)
            out.append('""')
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            i = j + 1
            out.append('""')
        elif c == "'" and re.match(r"'(\\.|[^\\'])'", text[i:i + 4]):
            i += len(re.match(r"'(\\.|[^\\'])'", text[i:i + 4]).group(0))
        else:
            out.append(c)
            i += 1
    return "".join(out)


def module_of(rel):
    first = rel.split(os.sep)[0]
    return first[:-3] if first.endswith(".rs") else first


def files():
    for root, _, names in os.walk("src"):
        for name in sorted(names):
            if name.endswith(".rs"):
                path = os.path.join(root, name)
                rel = os.path.relpath(path, "src")
                if rel in ("lib.rs",) or rel.startswith("bin" + os.sep):
                    continue  # the root re-exports; the program sits above everything
                yield path, rel


def crate_paths(text):
    """The first segment of every path into the crate in `text`: `crate::x::...`, each
    item of `crate::{x::..., Y, ...}` (nested groups included), and `super::...` (what the
    caller counts as the crate root only in a module's top file)."""
    out = set(re.findall(r"\bcrate::([A-Za-z_][A-Za-z0-9_]*)", text))
    for group in re.finditer(r"\bcrate::\{", text):
        depth, i, item, items = 1, group.end(), "", []
        while i < len(text) and depth:
            c = text[i]
            if c == "{":
                depth += 1
            elif c == "}":
                depth -= 1
            if depth == 1 and c == ",":
                items.append(item)
                item = ""
            elif depth >= 1 and not (depth == 1 and c == "}"):
                item += c if depth == 1 else ""
            i += 1
        items.append(item)
        for it in items:
            first = re.match(r"\s*([A-Za-z_][A-Za-z0-9_]*)", it)
            if first and first.group(1) not in ("self",):
                out.add(first.group(1))
    return out


def root_reexports():
    """Names the crate root re-exports (`pub use module::{A, B}` / `pub use module::A`),
    with the module each comes from."""
    text = code(os.path.join("src", "lib.rs"))
    names = {}
    for m in re.finditer(r"pub\s+use\s+([a-z_]+)::(\{[^}]*\}|[A-Za-z_][A-Za-z0-9_]*)\s*;", text):
        module, what = m.group(1), m.group(2)
        for name in re.findall(r"[A-Za-z_][A-Za-z0-9_]*", what):
            names[name] = module
    return names


def arrows(path, rel, text, reexported):
    """The problems of one file's imports (its path `rel` below src/, its code `text`)."""
    problems = []
    mod = module_of(rel)
    if mod not in RANK:
        return [f"{path}: module `{mod}` is not in the layer table of .ci/layers.py"]
    used_names = crate_paths(text)
    # `super::` climbs from the file's module (depth: its folders) to the crate root
    # after depth + 1 steps; one more allows for an inline `mod tests` inside it.
    depth = rel.count(os.sep)
    if re.search(r"\b(super::){%d,}" % (depth + 2), text):
        problems.append(
            f"{path}: a `super::` path reaches the crate root: name the module "
            f"(`crate::module::Item`)"
        )
    for used in sorted(used_names):
        if used in RANK:
            if used != mod and RANK[used] >= RANK[mod]:
                problems.append(
                    f"{path}: `{mod}` (layer {RANK[mod]}) imports `crate::{used}` "
                    f"(layer {RANK[used]}): only lower layers may be imported"
                )
        elif used in reexported:
            problems.append(
                f"{path}: `crate::{used}` goes through the crate root's re-export (the "
                f"root sits above every layer): write `crate::{reexported[used]}::{used}`"
            )
        elif used[0].isupper():
            problems.append(
                f"{path}: `crate::{used}` is no module of the layer table nor a name the "
                f"crate root re-exports: the check cannot place it"
            )
    return problems


def self_test(reexported):
    """Planted imports of every path form are caught, and lawful ones pass: the check
    can fail."""
    planted = [
        ("geometry.rs", "use crate::driver::Event;", True),
        ("geometry.rs", "fn f() -> crate::Event { todo!() }", True),
        ("geometry.rs", "use crate::{error::Error, driver::{Driver, Event}};", True),
        ("geometry.rs", "use crate::{Grid};", True),
        ("solver/fsai.rs", "use super::super::super::Event;", True),
        ("geometry.rs", "use crate::error::{Error, Result};", False),
        ("solver/fsai.rs", "use super::parallel::Parallelism;", False),
        ("solver/fsai.rs", "mod tests { use super::super::Entries; }", False),
    ]
    for rel, text, bad in planted:
        found = arrows(rel, rel, text, reexported)
        if bool(found) != bad:
            sys.exit(f".ci/layers.py self-test: {text!r} in {rel} gave {found}")


def main():
    os.chdir(os.path.join(os.path.dirname(__file__), ".."))
    problems = []
    reexported = root_reexports()
    self_test(reexported)
    # 1. Module layers. Every path form counts: `crate::module::...`, `crate::{...}`, a
    #    name the crate root re-exports (`crate::Event`: an arrow through the root, which
    #    sits above every layer), and `super::` paths that climb to the root.
    for path, rel in files():
        problems += arrows(path, rel, code(path), reexported)
    # 2. No circle among the sibling files of one module (`super::x::`). A parent file
    #    (`mod.rs`, `scene.rs`) and its children may use each other: the parent holds the
    #    type, the children its methods.
    graph = {}
    for path, rel in files():
        parts = rel[:-3].split(os.sep)
        if len(parts) == 1:
            continue
        node = rel[:-3]
        parent = os.sep.join(parts[:-1])
        siblings = {
            f[:-3]
            for f in os.listdir(os.path.join("src", parent))
            if f.endswith(".rs") and f != "mod.rs"
        }
        text = code(path)
        targets = set()
        for name in re.findall(r"\bsuper::([a-z_]+)::", text):
            if name in siblings:
                targets.add(os.path.join(parent, name))
        graph.setdefault(node, set()).update(t for t in targets if t != node)
    state = {}

    def visit(node, stack):
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                cycle = stack[stack.index(nxt):] + [nxt]
                problems.append("circle among files: " + " -> ".join(cycle))
            elif nxt not in state:
                visit(nxt, stack)
        stack.pop()
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node, [])
    if problems:
        print("\n".join(problems))
        sys.exit(1)
    print(f"layers: {len(RANK)} modules in {len(LAYERS)} layers, no upward import, no circle")


if __name__ == "__main__":
    main()
