#!/usr/bin/env bash
# Prepares the GPU checks of docs/gpu.md on a machine without a GPU: builds
# psa-esp and tests/gpu.rs with the `cuda` feature, and copies them with
# the ODE libraries they load into gpu-build/ (git-ignored), to carry to a
# machine that has only the NVIDIA driver and NVRTC.
#   --reference SEEDS  also runs the paper grid's first SEEDS seeds on
#                      `native` into gpu-build/native, and lists its files
#                      as --hashes does;
#   --hashes GRID      lists the SHA-256 of every file but run.json of the
#                      finished runs of GRID (scripts/gpu/digest.py) (a `replicate --preset paper`
#                      grid on `native`, finished or not) in
#                      gpu-build/NAME.sha256 (NAME: GRID's folder name), and
#                      the arguments that make the same grid in NAME.args,
#                      for check.sh to make it on the GPU and compare.
set -euo pipefail
cd "$(dirname "$0")/../.."
seeds=""
grids=()
while [ $# -gt 0 ]; do
    case "$1" in
        --reference) seeds="${2:?--reference needs a seed count}"; shift 2 ;;
        --hashes) grids+=("${2:?--hashes needs a grid folder}"); shift 2 ;;
        *) echo "usage: scripts/gpu/prepare.sh [--reference SEEDS] [--hashes GRID]..." >&2; exit 2 ;;
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
    grids+=(gpu-build/native)
fi
for grid in "${grids[@]}"; do
    name=$(basename "$grid")
    python3 - "$grid" > "gpu-build/$name.args" <<'PY'
import json, sys
grid = json.load(open(sys.argv[1] + "/grid.json"))
if grid.get("preset") != "paper" or grid.get("backend") != "native" or not grid.get("ode_check"):
    sys.exit(f"{sys.argv[1]}: not a `replicate --preset paper` grid on native")
print(f"--preset paper --seeds {grid['seeds']}")
PY
    scripts/gpu/digest.py "$grid" > "gpu-build/$name.sha256"
    echo "$grid: $(wc -l < "gpu-build/$name.sha256") files of $(grep -c robustness.json "gpu-build/$name.sha256") finished runs listed"
done
du -sh gpu-build
