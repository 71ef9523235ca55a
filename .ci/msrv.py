#!/usr/bin/env python3
"""Fails when a resolved package needs a newer rustc than the crate's `rust-version`.

Reads `cargo metadata --format-version 1` on stdin. Every resolved package counts,
dev-dependencies included: the README promises `cargo test --release --all-features` too.
"""
import json
import sys


def version(text):
    parts = [int(x) for x in text.split(".")]
    return tuple(parts + [0] * (3 - len(parts)))


meta = json.load(sys.stdin)
resolved = {node["id"] for node in meta["resolve"]["nodes"]}
root = next(p for p in meta["packages"] if p["id"] == meta["resolve"]["root"])
promised = root.get("rust_version")
if not promised:
    sys.exit("Cargo.toml has no rust-version")
too_new = sorted(
    (version(p["rust_version"]), p["name"], p["version"], p["rust_version"])
    for p in meta["packages"]
    if p["id"] in resolved
    and p.get("rust_version")
    and version(p["rust_version"]) > version(promised)
)
if too_new:
    lines = [f"  {name} {ver} needs rustc {rv}" for _, name, ver, rv in too_new]
    sys.exit(f"rust-version = {promised} in Cargo.toml, but:\n" + "\n".join(lines))
print(f"rust-version = {promised} covers all {len(resolved)} resolved packages")
