#!/usr/bin/env bash
# Tests scripts/nvrtc-check.py on planted copies of kernels.cu: a warning and a syntax
# error each fail it (exit 1, NVRTC's message printed), a source without kernels and a
# wheel without its library are bad inputs (exit 2). Needs python3 and the wheels (the
# check's cache, fetched on first use); .ci/run runs it after the check itself.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
check=("python3" "$here/nvrtc-check.py")
kernels="$here/../src/solver/cuda/kernels.cu"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0

# expect NAME CODE TEXT ARGS...: the check with ARGS exits CODE and prints TEXT.
expect() {
    local name=$1 code=$2 text=$3
    shift 3
    local got=0
    "${check[@]}" "$@" >"$tmp/$name.out" 2>&1 || got=$?
    if [ "$got" -ne "$code" ] || ! grep -qF -- "$text" "$tmp/$name.out"; then
        echo "FAILED $name: exit $got (expected $code), output:"
        sed 's/^/    /' "$tmp/$name.out"
        failures=$((failures + 1))
    else
        echo "ok     $name"
    fi
}

# A warning only (a variable never used): the compilation succeeds, the log fails it.
cp "$kernels" "$tmp/warning.cu"
echo '__device__ int planted_unused() { int x; return 0; }' >>"$tmp/warning.cu"
expect warning 1 'warning #177-D: variable "x" was declared but never referenced' --source "$tmp/warning.cu"

cp "$kernels" "$tmp/error.cu"
echo 'extern "C" __global__ void planted(int* a) { a[0] = ; }' >>"$tmp/error.cu"
expect error 1 "error: expected an expression" --source "$tmp/error.cu"

echo '__device__ int no_kernel() { return 0; }' >"$tmp/none.cu"
expect no-kernels 2 'has no extern "C" __global__ kernel' --source "$tmp/none.cu"

# A cache whose install is marked complete but lacks the library.
mkdir -p "$tmp/cache/nvidia-cuda-nvrtc-cu12-12.9.86"
touch "$tmp/cache/nvidia-cuda-nvrtc-cu12-12.9.86/.complete"
expect no-library 2 "has no nvidia/cuda_nvrtc/lib/libnvrtc.so.12" --cache "$tmp/cache"

if [ $failures -ne 0 ]; then
    echo "$failures test(s) of nvrtc-check.py failed"
    exit 1
fi
echo "nvrtc-check.py: all tests passed"
