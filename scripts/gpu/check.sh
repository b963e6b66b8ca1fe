#!/usr/bin/env bash
# The GPU checks of docs/gpu.md, on a machine with an NVIDIA GPU, from the
# repository's root with scripts/gpu/prepare.sh's gpu-build/ beside it, in
# about CHECK_SECONDS seconds (default 380). Writes into ${OUT:-gpu-check}:
#   device.txt     the device and its cores;
#   timeline.txt   when each step started;
#   tests.txt      tests/gpu.rs's GPU and NVRTC tests;
#   bench.txt      the kernel's rows (kernel alone and with copies, beside native);
#   shapes.txt     the kernel's rows at 400 and 312,000 networks in other shapes
#                  (SHAPES: "threads min-blocks unroll;..." ...);
#   grid-NAME.txt  for each gpu-build/NAME.sha256 (smallest first): the
#                  grid of NAME.args made on `cuda` in the time left, its
#                  wall time, and the listed files (a native grid's
#                  finished runs) that differ from it or are missing.
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
for test in "nvrtc 60" "the_gpu 150" "the_cuda_backend 30"; do
    set -- $test
    echo "$(date +%T) tests $1" >> "$out/timeline.txt"
    timeout "$2" gpu-build/gpu --test-threads 1 "$1" >> "$out/tests.txt" 2>&1
done
echo "$(date +%T) bench" >> "$out/timeline.txt"
timeout 120 "$bin" bench --kernel-only --rounds 5 > "$out/bench.txt" 2>&1
echo "$(date +%T) shapes" >> "$out/timeline.txt"
IFS=';' read -ra shapes <<< "${SHAPES:-128 1 1;128 3 2;128 4 1;64 8 1}"
for shape in "${shapes[@]}"; do
    # shellcheck disable=SC2086
    set -- $shape
    echo "PSA_ESP_CUDA_BLOCK=$1 PSA_ESP_CUDA_MIN_BLOCKS=$2 PSA_ESP_CUDA_UNROLL=$3" >> "$out/shapes.txt"
    PSA_ESP_CUDA_BLOCK=$1 PSA_ESP_CUDA_MIN_BLOCKS=$2 PSA_ESP_CUDA_UNROLL=$3 timeout 60 "$bin" bench --kernel-only \
        --rounds 3 --kernel-networks 400,312000 >> "$out/shapes.txt" 2>&1
done
for list in $(ls -S -r gpu-build/*.sha256 2>/dev/null); do
    name=$(basename "$list" .sha256)
    report="$out/grid-$name.txt"
    echo "$(date +%T) grid $name" >> "$out/timeline.txt"
    left=$(( deadline - $(date +%s) ))
    echo "replicate $(cat "gpu-build/$name.args") --backend cuda; time left: $left s" > "$report"
    [ "$left" -gt 20 ] || continue
    start=$(millis)
    # shellcheck disable=SC2046
    timeout "$left" "$bin" replicate $(cat "gpu-build/$name.args") --backend cuda --quiet \
        --out "$scratch/$name" >> "$report" 2>&1
    echo "exit $?; wall time: $(( $(millis) - start )) ms" >> "$report"
    echo "finished runs: $(find "$scratch/$name/runs" -name robustness.json 2>/dev/null | wc -l)" >> "$report"
    if [ -d "$scratch/$name/runs" ]; then
        scripts/gpu/digest.py "$scratch/$name" --against "$list" > "$out/grid-$name-differing.txt"
        tail -n 1 "$out/grid-$name-differing.txt" >> "$report"
    else
        echo "no grid written" >> "$report"
    fi
done
echo "$(date +%T) done" >> "$out/timeline.txt"
rm -rf "$scratch"
tail -n 40 "$out"/*.txt
