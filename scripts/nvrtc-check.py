#!/usr/bin/env python3
"""Compiles the CUDA backend's kernels.cu with NVRTC of CUDA 12 and of CUDA 13 (issue 57
item 4; docs/gpu.md), as the crate does on a GPU, but on any x86-64 Linux machine: NVRTC
needs no GPU and no driver. .ci/run runs it.

    scripts/nvrtc-check.py [--cache DIR] [--source FILE]

For each toolkit it takes NVRTC from NVIDIA's pip wheel (downloaded once into the cache,
by default target/nvrtc-wheels; about 150 MB for both), opens its libnvrtc with ctypes
and compiles the source to
  - PTX for compute_90,
  - PTX for NVRTC's default architecture (the crate's fallback when no binary compiles),
  - a binary (cubin) for sm_90 (the crate's first choice, for the GPU's own sm_XY),
with the crate's options: `-DTHREADS=N`, N read from kernels.rs's `THREADS` (the one
constant), `--gpu-architecture=...`, the program named `precursors_kernels.cu`. The PTX
must name every `extern "C"` kernel of the source and the binary must be an ELF file.

Any message in NVRTC's log fails it, a warning as much as an error. Exit status: 0 all
compiled without a message, 1 a compilation failed or left a message, 2 bad arguments or
NVRTC could not be fetched or opened. scripts/test-nvrtc-check.sh tests it.
"""

import argparse
import ctypes
import pathlib
import re
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
KERNELS_RS = ROOT / "src/solver/cuda/kernels.rs"
KERNELS_CU = ROOT / "src/solver/cuda/kernels.cu"
# The name the crate gives the program (kernels.rs), which NVRTC's messages quote.
PROGRAM_NAME = b"precursors_kernels.cu"

# (label, pip requirement, libnvrtc inside the installed wheel). Pinned, so that a new
# NVRTC release cannot turn CI red on its own; raise them deliberately.
TOOLKITS = [
    ("CUDA 12", "nvidia-cuda-nvrtc-cu12==12.9.86", "nvidia/cuda_nvrtc/lib/libnvrtc.so.12"),
    ("CUDA 13", "nvidia-cuda-nvrtc==13.5.37", "nvidia/cu13/lib/libnvrtc.so.13"),
]
ARCH = "90"  # the H200's compute capability 9.0


class Failure(Exception):
    """A compilation that failed or printed a message (exit 1)."""


class SetupError(Exception):
    """NVRTC not fetched or not opened, or the crate's options not found (exit 2)."""


def threads_from_rust(path: pathlib.Path) -> int:
    """kernels.rs's `THREADS`, the block size the crate passes as -DTHREADS."""
    found = re.findall(r"^pub\(super\) const THREADS: u32 = (\d+);$", path.read_text(), re.M)
    if len(found) != 1:
        raise SetupError(f"{path}: expected one `pub(super) const THREADS: u32 = N;`, found {len(found)}")
    return int(found[0])


def kernel_names(source: str) -> list:
    return re.findall(r'extern "C" __global__ void (\w+)\s*\(', source)


def fetch(cache: pathlib.Path, requirement: str, library: str) -> pathlib.Path:
    """The wheel installed under `cache` (pip, once; a stamp marks a complete install)."""
    dest = cache / requirement.replace("==", "-")
    stamp = dest / ".complete"
    if not stamp.exists():
        start = time.monotonic()
        command = [sys.executable, "-m", "pip", "install", "--quiet", "--disable-pip-version-check",
                   "--no-deps", "--no-compile", "--no-cache-dir", "--upgrade", "--target", str(dest), requirement]
        done = subprocess.run(command, capture_output=True, text=True)
        if done.returncode != 0:
            raise SetupError(f"pip could not install {requirement}: {done.stderr.strip()[-800:]}")
        size = sum(f.stat().st_size for f in dest.rglob("*") if f.is_file())
        print(f"   fetched {requirement}: {size / 1e6:.0f} MB installed in {time.monotonic() - start:.1f} s")
        stamp.write_text("")
    path = dest / library
    if not path.is_file():
        raise SetupError(f"{requirement} has no {library}")
    return path


class Nvrtc:
    """The few NVRTC calls the check needs, through ctypes."""

    def __init__(self, path: pathlib.Path):
        try:
            self.lib = ctypes.CDLL(str(path))
        except OSError as e:
            raise SetupError(f"cannot open {path}: {e}")
        self.lib.nvrtcGetErrorString.restype = ctypes.c_char_p
        major, minor = ctypes.c_int(), ctypes.c_int()
        self.call("nvrtcVersion", ctypes.byref(major), ctypes.byref(minor))
        self.version = f"{major.value}.{minor.value}"

    def call(self, name: str, *args):
        code = getattr(self.lib, name)(*args)
        if code != 0:
            raise Failure(f"{name}: {self.lib.nvrtcGetErrorString(code).decode()}")

    def compile(self, source: bytes, options: list, binary: bool):
        """(the output, NVRTC's log) of one compilation; a failed one raises with its log."""
        program = ctypes.c_void_p()
        self.call("nvrtcCreateProgram", ctypes.byref(program), source, PROGRAM_NAME, 0, None, None)
        try:
            argv = (ctypes.c_char_p * len(options))(*[o.encode() for o in options])
            code = self.lib.nvrtcCompileProgram(program, len(options), argv)
            size = ctypes.c_size_t()
            self.call("nvrtcGetProgramLogSize", program, ctypes.byref(size))
            log = ctypes.create_string_buffer(size.value)
            self.call("nvrtcGetProgramLog", program, log)
            log = log.value.decode(errors="replace").strip()
            if code != 0:
                message = self.lib.nvrtcGetErrorString(code).decode()
                raise Failure(f"nvrtcCompileProgram: {message}\n{log}")
            kind = "CUBIN" if binary else "PTX"
            self.call(f"nvrtcGet{kind}Size", program, ctypes.byref(size))
            out = ctypes.create_string_buffer(size.value)
            self.call(f"nvrtcGet{kind}", program, out)
            return out.raw, log
        finally:
            self.call("nvrtcDestroyProgram", ctypes.byref(program))


def check(nvrtc: Nvrtc, source: str, threads: int) -> int:
    """Every target compiled; prints one line each. The number of failures."""
    define = f"-DTHREADS={threads}"
    names = kernel_names(source)
    targets = [
        (f"PTX compute_{ARCH}", [f"--gpu-architecture=compute_{ARCH}", define], False),
        ("PTX default arch", [define], False),
        (f"binary sm_{ARCH}", [f"--gpu-architecture=sm_{ARCH}", define], True),
    ]
    failures = 0
    for label, options, binary in targets:
        start = time.monotonic()
        try:
            out, log = nvrtc.compile(source.encode(), options, binary)
            if log:
                raise Failure(f"NVRTC's log is not empty (a warning fails the check):\n{log}")
            if binary and not out.startswith(b"\x7fELF"):
                raise Failure("the binary is not an ELF file")
            if not binary:
                ptx = out.decode(errors="replace")
                missing = [n for n in names if f".entry {n}(" not in ptx]
                if missing:
                    raise Failure(f"the PTX has no entry for {', '.join(missing)}")
                target = re.search(r"^\.target (\w+)", ptx, re.M)
            what = f"{len(out) / 1e3:.0f} kB" + ("" if binary else f", .target {target and target[1]}, {len(names)} kernels")
            print(f"   {label:<18} ok ({what}, {time.monotonic() - start:.1f} s) {' '.join(options)}")
        except Failure as e:
            failures += 1
            text = str(e).replace("\n", "\n      ")
            print(f"   {label:<18} FAILED {' '.join(options)}\n      {text}")
    return failures


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cache", type=pathlib.Path, default=ROOT / "target/nvrtc-wheels",
                        help="where the wheels are installed (default: target/nvrtc-wheels)")
    parser.add_argument("--source", type=pathlib.Path, default=KERNELS_CU,
                        help="the CUDA source (default: src/solver/cuda/kernels.cu)")
    args = parser.parse_args()
    try:
        source = args.source.read_text()
        threads = threads_from_rust(KERNELS_RS)
        if not kernel_names(source):
            raise SetupError(f"{args.source} has no extern \"C\" __global__ kernel")
        failures = 0
        for label, requirement, library in TOOLKITS:
            path = fetch(args.cache, requirement, library)
            nvrtc = Nvrtc(path)
            print(f"== {label}: NVRTC {nvrtc.version} ({requirement}), {args.source.name}, THREADS = {threads}")
            failures += check(nvrtc, source, threads)
    except (OSError, SetupError) as e:
        print(f"nvrtc-check: {e}", file=sys.stderr)
        return 2
    except Failure as e:
        print(f"nvrtc-check: {e}", file=sys.stderr)
        return 1
    if failures:
        print(f"nvrtc-check: {failures} compilation(s) failed or left a message")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
