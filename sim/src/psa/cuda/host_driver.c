/*
 * The host build of trial.cu as a program, for the tests: reads a launch
 * from standard input (four int32 counts: trials, neuron genes, network
 * row entries and noise words; then the PsaParams, the genes, the rows, the
 * PsaTrials and the noise words, as the machine lays them out) and writes
 * each trial's points (double) then its finite flag (int32). Compiled at
 * run time by `cuda::host` with the host C compiler, -ffp-contract=off and
 * the specialisation's -D options, as NVRTC compiles trial.cu for the GPU.
 */
#include <stdio.h>
#include <stdlib.h>

#include "trial.cu"

static void read_exactly(void *buffer, size_t size, size_t count) {
    if (count > 0 && fread(buffer, size, count, stdin) != count) {
        fprintf(stderr, "psa-trial-host: the launch on standard input is truncated\n");
        exit(2);
    }
}

static void *allocate(size_t size, size_t count) {
    void *buffer = malloc(size * (count + 1));
    if (!buffer) {
        fprintf(stderr, "psa-trial-host: out of memory\n");
        exit(2);
    }
    return buffer;
}

int main(void) {
    int32_t counts[4];
    PsaParams params;
    read_exactly(counts, sizeof counts[0], 4);
    for (int c = 0; c < 4; c++) {
        if (counts[c] < 0) {
            fprintf(stderr, "psa-trial-host: negative counts\n");
            return 2;
        }
    }
    size_t trials_count = (size_t)counts[0];
    read_exactly(&params, sizeof params, 1);
    double *neurons = allocate(sizeof(double), (size_t)counts[1]);
    int *networks = allocate(sizeof(int), (size_t)counts[2]);
    PsaTrial *trials = allocate(sizeof(PsaTrial), trials_count);
    psa_u64 *noise = allocate(sizeof(psa_u64), (size_t)counts[3]);
    double *points = allocate(sizeof(double), trials_count);
    int *finite = allocate(sizeof(int), trials_count);
    read_exactly(neurons, sizeof(double), (size_t)counts[1]);
    read_exactly(networks, sizeof(int), (size_t)counts[2]);
    read_exactly(trials, sizeof(PsaTrial), trials_count);
    read_exactly(noise, sizeof(psa_u64), (size_t)counts[3]);
    psa_trials_host(&params, neurons, networks, trials, noise, counts[0], points, finite);
    fwrite(points, sizeof(double), trials_count, stdout);
    fwrite(finite, sizeof(int), trials_count, stdout);
    return fflush(stdout) == 0 ? 0 : 2;
}
