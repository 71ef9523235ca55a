#!/usr/bin/env python3
"""The crate's public API as a sorted listing, compared with the checked-in one.

    python3 .ci/api.py check    # CI: fails when the API differs from api/public-api.txt
    python3 .ci/api.py update   # rewrites api/public-api.txt after a deliberate change

The listing comes from rustdoc's JSON output of the library with all features
(`RUSTC_BOOTSTRAP=1 cargo rustdoc --lib --all-features -- -Z unstable-options
--output-format json`: the stable toolchain, nothing to install). One line per public
path: modules, types with their attributes (`#[non_exhaustive]`), public fields, enum
variants with their fields, functions and methods with their full signatures, constants,
and the traits each public type implements (auto traits included: losing `Send` breaks
callers). docs/compatibility.md says what semver covers.

`check` sorts the differences into removed or changed lines (an incompatible change: the
major version must change) and added lines (a compatible addition: update the listing in
the same commit, with a CHANGELOG entry). Either fails, so the listing is always the API.
It also compares the API with each release's listing of the crate's major version
(`api/public-api-X.Y.Z.txt`, written at the release): a line of a release that is gone
fails, so 1.x only adds to what 1.0.0 promised, whatever the working listing says.
"""
import json
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LISTING = os.path.join(ROOT, "api", "public-api.txt")
RELEASE = re.compile(r"public-api-(\d+)\.(\d+)\.(\d+)\.txt$")
CRATE = "precursors"
# rustdoc's JSON changes its format between toolchains; these are the versions this
# script was written against (an unknown one is refused with this message).
FORMATS = range(53, 60)
# Traits no caller can name or rely on (compiler internals); the other auto traits (Send,
# Sync, Unpin, UnwindSafe, RefUnwindSafe) are listed.
NOT_PROMISED = {"Freeze", "StructuralPartialEq", "UnsafeUnpin"}


def rustdoc_json():
    target = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
    env = dict(os.environ, RUSTC_BOOTSTRAP="1")
    subprocess.run(
        ["cargo", "rustdoc", "--lib", "--all-features", "--quiet", "--",
         "-Z", "unstable-options", "--output-format", "json"],
        cwd=ROOT, env=env, check=True)
    with open(os.path.join(target, "doc", CRATE + ".json")) as f:
        doc = json.load(f)
    if doc["format_version"] not in FORMATS:
        sys.exit(f"rustdoc JSON format {doc['format_version']} is not one this script "
                 f"reads ({FORMATS.start}..{FORMATS.stop - 1}); adapt .ci/api.py")
    return doc


class Lister:
    def __init__(self, doc):
        self.doc = doc
        self.index = doc["index"]
        self.paths = doc["paths"]
        self.lines = []
        # id -> the shortest public path, so a signature names a type as users do, and
        # moving an item between private modules does not change the listing.
        self.public_paths = {}

    def item(self, id_):
        return self.index[str(id_)]

    # -- types ---------------------------------------------------------------------
    def path_of(self, resolved):
        entry = self.paths.get(str(resolved["id"]))
        public = self.public_paths.get(resolved["id"])
        if public is not None:
            name = public
        elif entry is not None:
            name = "::".join(entry["path"])
        else:
            name = resolved["path"]
        return name + self.args(resolved.get("args"))

    def args(self, args):
        if not args:
            return ""
        if "angle_bracketed" in args:
            parts = []
            for a in args["angle_bracketed"]["args"]:
                if "type" in a:
                    parts.append(self.ty(a["type"]))
                elif "lifetime" in a:
                    parts.append(a["lifetime"])
                elif "const" in a:
                    parts.append(a["const"].get("expr", "_"))
                else:
                    parts.append("_")
            for c in args["angle_bracketed"].get("constraints", []):
                binding = c.get("binding", {})
                if "equality" in binding:
                    value = binding["equality"]
                    value = self.ty(value["type"]) if "type" in value else str(value)
                    parts.append(f"{c['name']} = {value}")
                else:
                    parts.append(f"{c['name']}: {self.bounds(binding.get('constraint', []))}")
            return "<" + ", ".join(parts) + ">" if parts else ""
        if "parenthesized" in args:
            p = args["parenthesized"]
            out = "(" + ", ".join(self.ty(t) for t in p["inputs"]) + ")"
            if p.get("output"):
                out += " -> " + self.ty(p["output"])
            return out
        return ""

    def bounds(self, bounds):
        parts = []
        for b in bounds:
            if "trait_bound" in b:
                tb = b["trait_bound"]
                parts.append(("?" if tb.get("modifier") == "maybe" else "")
                             + self.path_of(tb["trait"]))
            elif "outlives" in b:
                parts.append(b["outlives"])
            else:
                parts.append("_")
        return " + ".join(parts)

    def ty(self, t):
        (kind, v), = t.items()
        if kind == "primitive":
            return v
        if kind == "generic":
            return v
        if kind == "resolved_path":
            return self.path_of(v)
        if kind == "borrowed_ref":
            life = (v["lifetime"] + " ") if v.get("lifetime") else ""
            return "&" + life + ("mut " if v["is_mutable"] else "") + self.ty(v["type"])
        if kind == "slice":
            return "[" + self.ty(v) + "]"
        if kind == "array":
            return f"[{self.ty(v['type'])}; {v['len']}]"
        if kind == "tuple":
            return "(" + ", ".join(self.ty(x) for x in v) + ("," if len(v) == 1 else "") + ")"
        if kind == "impl_trait":
            return "impl " + self.bounds(v)
        if kind == "dyn_trait":
            parts = [self.path_of(p["trait"]) for p in v["traits"]]
            if v.get("lifetime"):
                parts.append(v["lifetime"])
            return "dyn " + " + ".join(parts)
        if kind == "qualified_path":
            trait = self.path_of(v["trait"]) if v.get("trait") else ""
            return f"<{self.ty(v['self_type'])} as {trait}>::{v['name']}"
        if kind == "raw_pointer":
            return ("*mut " if v["is_mutable"] else "*const ") + self.ty(v["type"])
        if kind == "function_pointer":
            sig = v["sig"]
            out = "fn(" + ", ".join(self.ty(t) for _, t in sig["inputs"]) + ")"
            if sig.get("output"):
                out += " -> " + self.ty(sig["output"])
            return out
        return kind

    def generics(self, g):
        params = []
        for p in g["params"]:
            kind = p["kind"]
            if "lifetime" in kind:
                params.append(p["name"])
            elif "type" in kind:
                if kind["type"].get("is_synthetic"):
                    continue  # `impl Trait` in argument position, shown there
                b = self.bounds(kind["type"].get("bounds", []))
                params.append(p["name"] + (": " + b if b else ""))
            elif "const" in kind:
                params.append(f"const {p['name']}: {self.ty(kind['const']['type'])}")
        where = []
        for w in g.get("where_predicates", []):
            if "bound_predicate" in w:
                bp = w["bound_predicate"]
                where.append(f"{self.ty(bp['type'])}: {self.bounds(bp['bounds'])}")
        return ("<" + ", ".join(params) + ">" if params else ""), (
            " where " + ", ".join(where) if where else "")

    def signature(self, name, f):
        sig = f["sig"]
        gen, where = self.generics(f["generics"])
        inputs = []
        for arg, t in sig["inputs"]:
            if arg == "self":
                rendered = self.ty(t)
                inputs.append({"Self": "self", "&Self": "&self",
                               "&mut Self": "&mut self"}.get(rendered, "self: " + rendered))
            else:
                inputs.append(f"{arg}: {self.ty(t)}")
        header = f["header"]
        quals = ("const " if header.get("is_const") else "") + (
            "unsafe " if header.get("is_unsafe") else "")
        out = f"{quals}fn {name}{gen}(" + ", ".join(inputs) + ")"
        if sig.get("output"):
            out += " -> " + self.ty(sig["output"])
        return out + where

    # -- items ---------------------------------------------------------------------
    @staticmethod
    def attrs(item):
        shown = []
        for a in item.get("attrs", []):
            text = a if isinstance(a, str) else json.dumps(a)
            if "non_exhaustive" in text:
                shown.append("#[non_exhaustive] ")
        return "".join(shown)

    def emit(self, line):
        self.lines.append(line)

    def module(self, id_, path):
        m = self.item(id_)
        for cid in m["inner"]["module"]["items"]:
            c = self.item(cid)
            if c["visibility"] != "public":
                continue
            (kind, inner), = c["inner"].items()
            if kind == "use":
                target = inner["id"]
                if target is None or str(target) not in self.index:
                    # A re-export of another crate (e.g. `pub use nalgebra`).
                    self.emit(f"pub use {path}::{inner['name']} = {inner['source']}")
                    continue
                if inner["is_glob"]:
                    t = self.item(target)
                    if "module" in t["inner"]:
                        for gid in t["inner"]["module"]["items"]:
                            self.public(gid, path)
                    continue
                self.public(target, path, inner["name"])
            else:
                self.public(cid, path)

    def public(self, id_, path, name=None):
        c = self.item(id_)
        if c["visibility"] != "public" and name is None:
            return
        (kind, inner), = c["inner"].items()
        name = name or c["name"]
        full = f"{path}::{name}"
        known = self.public_paths.get(id_)
        if known is None or (full.count("::"), full) < (known.count("::"), known):
            self.public_paths[id_] = full
        a = self.attrs(c)
        if kind == "module":
            self.emit(f"pub mod {full}")
            self.module(id_, full)
        elif kind == "struct":
            gen, where = self.generics(inner["generics"])
            self.emit(f"{a}pub struct {full}{gen}{where}")
            skind = inner["kind"]
            if "plain" in skind:
                for fid in skind["plain"]["fields"]:
                    f = self.item(fid)
                    if f["visibility"] == "public":
                        self.emit(f"pub {full}.{f['name']}: {self.ty(f['inner']['struct_field'])}")
                if skind["plain"].get("has_stripped_fields"):
                    self.emit(f"{full}: private fields")
            elif "tuple" in skind:
                for i, fid in enumerate(skind["tuple"]):
                    if fid is None:
                        continue
                    f = self.item(fid)
                    if f["visibility"] == "public":
                        self.emit(f"pub {full}.{i}: {self.ty(f['inner']['struct_field'])}")
            self.impls(full, inner["impls"])
        elif kind == "enum":
            gen, where = self.generics(inner["generics"])
            self.emit(f"{a}pub enum {full}{gen}{where}")
            for vid in inner["variants"]:
                v = self.item(vid)
                vk = v["inner"]["variant"]["kind"]
                va = self.attrs(v)
                if vk == "plain":
                    self.emit(f"{va}{full}::{v['name']}")
                elif "tuple" in vk:
                    fields = [self.ty(self.item(f)["inner"]["struct_field"])
                              for f in vk["tuple"] if f is not None]
                    self.emit(f"{va}{full}::{v['name']}(" + ", ".join(fields) + ")")
                elif "struct" in vk:
                    fields = [f"{self.item(f)['name']}: {self.ty(self.item(f)['inner']['struct_field'])}"
                              for f in vk["struct"]["fields"]]
                    self.emit(f"{va}{full}::{v['name']} {{ " + ", ".join(fields) + " }")
            self.impls(full, inner["impls"])
        elif kind == "function":
            self.emit(f"pub {self.signature(full, inner)}")
        elif kind == "constant":
            self.emit(f"pub const {full}: {self.ty(inner['type'])}")
        elif kind == "static":
            self.emit(f"pub static {full}: {self.ty(inner['type'])}")
        elif kind == "type_alias":
            gen, _ = self.generics(inner["generics"])
            self.emit(f"pub type {full}{gen} = {self.ty(inner['type'])}")
        elif kind == "trait":
            self.emit(f"{a}pub trait {full}")
            for iid in inner["items"]:
                it = self.item(iid)
                if "function" in it["inner"]:
                    self.emit(f"{full}::{self.signature(it['name'], it['inner']['function'])}")
        elif kind == "macro":
            self.emit(f"pub macro {full}!")
        else:
            self.emit(f"pub {kind} {full}")

    def impls(self, full, impl_ids):
        for iid in impl_ids:
            im = self.item(iid)["inner"]["impl"]
            if im.get("blanket_impl") is not None:
                continue
            if im["trait"] is not None:
                if im["trait"]["path"].split("::")[-1] in NOT_PROMISED:
                    continue
                trait = self.path_of(im["trait"])
                neg = "!" if im.get("is_negative") else ""
                self.emit(f"impl {neg}{trait} for {full}")
                continue
            for mid in im["items"]:
                m = self.item(mid)
                if m["visibility"] != "public":
                    continue
                (kind, inner), = m["inner"].items()
                if kind == "function":
                    self.emit(f"pub {self.signature(full + '::' + m['name'], inner)}")
                elif kind == "assoc_const":
                    self.emit(f"pub const {full}::{m['name']}: {self.ty(inner['type'])}")


def listing():
    doc = rustdoc_json()
    lister = Lister(doc)
    lister.module(doc["root"], CRATE)  # first pass: the public path of every item
    lister.lines = []
    lister.module(doc["root"], CRATE)
    lines = set(re.sub(r"\s+", " ", line) for line in lister.lines)
    return sorted(lines, key=sort_key)


def sort_key(line):
    """Lines of one item together: by the item's path, then by the line."""
    match = re.search(CRATE + r"::[A-Za-z0-9_:]*", line)
    return (match.group(0) if match else line, line)


def main():
    mode = sys.argv[1] if len(sys.argv) > 1 else "check"
    current = listing()
    if mode == "update":
        os.makedirs(os.path.dirname(LISTING), exist_ok=True)
        with open(LISTING, "w") as f:
            f.write("\n".join(current) + "\n")
        print(f"wrote {len(current)} lines to {os.path.relpath(LISTING, ROOT)}")
        return
    if mode != "check":
        sys.exit("usage: .ci/api.py check|update")
    with open(LISTING) as f:
        recorded = [line for line in f.read().splitlines() if line]
    removed = sorted(set(recorded) - set(current))
    added = sorted(set(current) - set(recorded))
    if removed:
        print("The public API changed incompatibly against api/public-api.txt (what 1.x "
              "promises, docs/compatibility.md): these items are gone or changed:")
        for line in removed:
            print("  - " + line)
    if added:
        print("The public API gained items not in api/public-api.txt (a compatible "
              "addition: run `python3 .ci/api.py update`, commit the listing with a "
              "CHANGELOG entry):")
        for line in added:
            print("  + " + line)
    broken = releases_broken(set(current))
    if removed or added or broken:
        sys.exit(1)
    print(f"public API unchanged ({len(current)} lines)")


def crate_major():
    with open(os.path.join(ROOT, "Cargo.toml")) as f:
        version = re.search(r'^version = "(\d+)\.', f.read(), re.M)
    return int(version.group(1))


def releases_broken(current):
    """Whether an item of a release of this major version is gone (printing each)."""
    major, broken = crate_major(), False
    folder = os.path.dirname(LISTING)
    for name in sorted(os.listdir(folder)):
        m = RELEASE.search(name)
        if not m or int(m.group(1)) != major:
            continue
        with open(os.path.join(folder, name)) as f:
            promised = {line for line in f.read().splitlines() if line}
        gone = sorted(promised - current)
        if gone:
            broken = True
            print(f"Items of the release listing {name} are gone or changed (an "
                  f"incompatible change within {major}.x, docs/compatibility.md):")
            for line in gone:
                print("  - " + line)
    return broken


if __name__ == "__main__":
    main()
