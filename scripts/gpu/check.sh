#!/usr/bin/env bash
# The GPU checks of docs/gpu.md, on a machine with an NVIDIA GPU, from the
# repository's root with scripts/gpu/prepare.sh's gpu-build/ beside it.
# Writes into ${OUT:-gpu-check}: the device, the GPU tests' output, the
# bench (its last table holds the kernel's rows) and, where
# gpu-build/native holds a reference grid, the same grid on `cuda` with
# its wall time and the list of run files that differ (none is the pass).
set -uo pipefail
cd "$(dirname "$0")/../.."
out="${OUT:-gpu-check}"
mkdir -p "$out"
export LD_LIBRARY_PATH="$PWD/gpu-build/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export PSA_ESP_BIN="$PWD/gpu-build/psa-esp"
nvidia-smi -L > "$out/device.txt" 2>&1
# The tests that need the GPU or NVRTC (the host-build ones need the build tree).
for filter in nvrtc the_gpu the_cuda_backend; do
    gpu-build/gpu --test-threads 1 "$filter" >> "$out/tests.txt" 2>&1
done
"$PSA_ESP_BIN" bench --rounds 3 --generations 20 > "$out/bench.txt" 2>&1
if [ -d gpu-build/native ]; then
    seeds=$(python3 -c 'import json; print(json.load(open("gpu-build/native/grid.json"))["seeds"])')
    start=$(date +%s%N)
    "$PSA_ESP_BIN" replicate --preset paper --no-ode-check --seeds "$seeds" --backend cuda --quiet \
        --out "$out/cuda" > "$out/grid.txt" 2>&1
    echo "wall time: $(( ($(date +%s%N) - start) / 1000000 )) ms" >> "$out/grid.txt"
    (cd gpu-build/native && find runs -type f ! -name run.json | sort) | while read -r f; do
        cmp -s "gpu-build/native/$f" "$out/cuda/$f" || echo "$f"
    done > "$out/differing-files.txt"
    echo "$(wc -l < "$out/differing-files.txt") run files differ" >> "$out/grid.txt"
fi
cat "$out"/*.txt
