#!/usr/bin/env bash
# Prepares the GPU checks of docs/gpu.md on a machine without a GPU: builds
# psa-esp and tests/gpu.rs with the `cuda` feature, and copies them with
# the ODE libraries they load into gpu-build/ (git-ignored), to carry to a
# machine that has only the NVIDIA driver and NVRTC.
#   --reference SEEDS  also runs the paper grid's first SEEDS seeds on
#                      `native` into gpu-build/native, for check.sh to
#                      compare the GPU's grid with, file for file;
#   --hashes GRID      also lists the SHA-256 of every file of GRID's
#                      finished runs but run.json (a `replicate --preset
#                      paper` grid on `native`, finished or not) in
#                      gpu-build/paper.sha256, for check.sh to compare the
#                      whole paper grid on the GPU with.
set -euo pipefail
cd "$(dirname "$0")/../.."
seeds=""
hashes=""
while [ $# -gt 0 ]; do
    case "$1" in
        --reference) seeds="${2:?--reference needs a seed count}"; shift 2 ;;
        --hashes) hashes="${2:?--hashes needs a grid folder}"; shift 2 ;;
        *) echo "usage: scripts/gpu/prepare.sh [--reference SEEDS] [--hashes GRID]" >&2; exit 2 ;;
    esac
done
.ci/install-deps
cargo build --release --features cuda
tests=$(cargo test --release --features cuda --test gpu --no-run --message-format=json 2>/dev/null |
    python3 -c 'import json,sys
for line in sys.stdin:
    m = json.loads(line)
    if m.get("reason") == "compiler-artifact" and m["target"]["name"] == "gpu" and m.get("executable"):
        print(m["executable"])')
rm -rf gpu-build/lib gpu-build/psa-esp gpu-build/gpu
mkdir -p gpu-build/lib
cp target/release/psa-esp gpu-build/psa-esp
cp "$tests" gpu-build/gpu
for lib in $(ldd target/release/psa-esp | awk '/lib(ode|ccd)/ {print $3}'); do
    cp -L "$lib" gpu-build/lib/
done
if [ -n "$seeds" ]; then
    rm -rf gpu-build/native
    target/release/psa-esp replicate --preset paper --seeds "$seeds" --quiet --out gpu-build/native
fi
if [ -n "$hashes" ]; then
    grep -q '"preset": "paper"' "$hashes/grid.json" || { echo "$hashes is not a paper-preset grid" >&2; exit 2; }
    (cd "$hashes" && find runs -name robustness.json -printf '%h\n' | sort |
        while read -r run; do find "$run" -type f ! -name run.json; done | sort | xargs sha256sum) \
        > gpu-build/paper.sha256.part
    mv gpu-build/paper.sha256.part gpu-build/paper.sha256
    echo "$(wc -l < gpu-build/paper.sha256) files of $(grep -c robustness.json gpu-build/paper.sha256) finished runs listed"
fi
du -sh gpu-build
