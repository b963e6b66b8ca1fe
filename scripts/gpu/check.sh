#!/usr/bin/env bash
# The GPU checks of docs/gpu.md, on a machine with an NVIDIA GPU, from the
# repository's root with scripts/gpu/prepare.sh's gpu-build/ beside it, in
# about CHECK_SECONDS seconds (default 380). Writes into ${OUT:-gpu-check}:
#   device.txt     the device;
#   tests.txt      tests/gpu.rs's GPU and NVRTC tests;
#   bench.txt      the kernel's rows (kernel alone and with copies, beside native);
#   shapes.txt     the kernel's row at 312,000 networks in other block shapes;
#   grid-1.txt     where gpu-build/native holds a reference grid: the same
#                  grid on `cuda`, its wall time and the run files that differ;
#   grid-paper.txt where gpu-build/paper.sha256 lists a paper grid's files:
#                  `replicate --preset paper --backend cuda` in the time
#                  left, its wall time, and the listed files that differ.
set -uo pipefail
cd "$(dirname "$0")/../.."
out="${OUT:-gpu-check}"
mkdir -p "$out"
deadline=$(( $(date +%s) + ${CHECK_SECONDS:-380} ))
export LD_LIBRARY_PATH="$PWD/gpu-build/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export PSA_ESP_BIN="$PWD/gpu-build/psa-esp"
bin="$PSA_ESP_BIN"
scratch=$(mktemp -d)
millis() { date +%s%N | cut -c1-13; }
nvidia-smi -L > "$out/device.txt" 2>&1
nproc >> "$out/device.txt"
# The tests that need the GPU or NVRTC (the host-build ones need the build tree).
for filter in nvrtc the_gpu the_cuda_backend; do
    timeout 150 gpu-build/gpu --test-threads 1 "$filter" >> "$out/tests.txt" 2>&1
done
timeout 120 "$bin" bench --kernel-only --rounds 5 > "$out/bench.txt" 2>&1
for shape in "64 1" "32 1" "128 3" "64 6"; do
    set -- $shape
    echo "PSA_ESP_CUDA_BLOCK=$1 PSA_ESP_CUDA_MIN_BLOCKS=$2" >> "$out/shapes.txt"
    PSA_ESP_CUDA_BLOCK=$1 PSA_ESP_CUDA_MIN_BLOCKS=$2 timeout 60 "$bin" bench --kernel-only --rounds 3 \
        --kernel-networks 312000 >> "$out/shapes.txt" 2>&1
done
if [ -d gpu-build/native ]; then
    seeds=$(python3 -c 'import json; print(json.load(open("gpu-build/native/grid.json"))["seeds"])')
    start=$(millis)
    timeout 200 "$bin" replicate --preset paper --seeds "$seeds" --backend cuda --quiet \
        --out "$scratch/grid-1" > "$out/grid-1.txt" 2>&1
    echo "exit $?; wall time: $(( $(millis) - start )) ms" >> "$out/grid-1.txt"
    (cd gpu-build/native && find runs -type f ! -name run.json | sort) | while read -r f; do
        cmp -s "gpu-build/native/$f" "$scratch/grid-1/$f" || echo "$f"
    done > "$out/grid-1-differing.txt"
    echo "$(wc -l < "$out/grid-1-differing.txt") of $(cd gpu-build/native && find runs -type f ! -name run.json | wc -l) run files differ" >> "$out/grid-1.txt"
fi
if [ -f gpu-build/paper.sha256 ]; then
    left=$(( deadline - $(date +%s) ))
    echo "time left for the paper grid: $left s" > "$out/grid-paper.txt"
    if [ "$left" -gt 30 ]; then
        start=$(millis)
        timeout "$left" "$bin" replicate --preset paper --backend cuda --quiet \
            --out "$scratch/paper" >> "$out/grid-paper.txt" 2>&1
        echo "exit $?; wall time: $(( $(millis) - start )) ms" >> "$out/grid-paper.txt"
        echo "finished runs: $(find "$scratch/paper/runs" -name robustness.json | wc -l)" >> "$out/grid-paper.txt"
        (cd "$scratch/paper" && sha256sum --quiet -c "$OLDPWD/gpu-build/paper.sha256") > "$out/grid-paper-differing.txt" 2>&1
        echo "$(grep -c ": FAILED" "$out/grid-paper-differing.txt") of $(wc -l < gpu-build/paper.sha256) listed files differ or are missing" >> "$out/grid-paper.txt"
    fi
fi
rm -rf "$scratch"
tail -n 40 "$out"/*.txt
