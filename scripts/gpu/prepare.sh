#!/usr/bin/env bash
# Prepares the GPU checks of docs/gpu.md on a machine without a GPU: builds
# psa-esp and tests/gpu.rs with the `cuda` feature, and copies them with
# the ODE libraries they load into gpu-build/ (git-ignored), to carry to a
# machine that has only the NVIDIA driver and NVRTC. With --reference
# SEEDS, also runs the paper grid's first SEEDS seeds on `native` into
# gpu-build/native, for scripts/gpu/check.sh to compare the GPU's grid with.
set -euo pipefail
cd "$(dirname "$0")/../.."
seeds=""
case "${1:-}" in
  "") ;;
  --reference) seeds="${2:?--reference needs a seed count}" ;;
  *) echo "usage: scripts/gpu/prepare.sh [--reference SEEDS]" >&2; exit 2 ;;
esac
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
    target/release/psa-esp replicate --preset paper --no-ode-check --seeds "$seeds" --quiet --out gpu-build/native
fi
du -sh gpu-build
