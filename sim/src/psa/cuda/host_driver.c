/*
 * The host build of trial.cu as a program, for the tests: reads a batch
 * from standard input (int32 trial count, int32 weight count, then the
 * PsaParams, the weights and the PsaTrials, as the machine lays them out)
 * and writes each trial's points (double) then its finite flag (int32).
 * Built by build.rs with the host C compiler and -ffp-contract=off.
 */
#include <stdio.h>
#include <stdlib.h>

#include "trial.cu"

static void read_exactly(void *buffer, size_t size, size_t count) {
    if (count > 0 && fread(buffer, size, count, stdin) != count) {
        fprintf(stderr, "psa-trial-host: the batch on standard input is truncated\n");
        exit(2);
    }
}

int main(void) {
    int32_t header[2];
    PsaParams params;
    read_exactly(header, sizeof header[0], 2);
    if (header[0] < 0 || header[1] < 0) {
        fprintf(stderr, "psa-trial-host: negative counts\n");
        return 2;
    }
    read_exactly(&params, sizeof params, 1);
    double *weights = malloc(sizeof(double) * (size_t)(header[1] + 1));
    PsaTrial *trials = malloc(sizeof(PsaTrial) * (size_t)(header[0] + 1));
    double *points = malloc(sizeof(double) * (size_t)(header[0] + 1));
    int *finite = malloc(sizeof(int) * (size_t)(header[0] + 1));
    if (!weights || !trials || !points || !finite) {
        fprintf(stderr, "psa-trial-host: out of memory\n");
        return 2;
    }
    read_exactly(weights, sizeof(double), (size_t)header[1]);
    read_exactly(trials, sizeof(PsaTrial), (size_t)header[0]);
    psa_trials_host(&params, weights, trials, header[0], points, finite);
    fwrite(points, sizeof(double), (size_t)header[0], stdout);
    fwrite(finite, sizeof(int), (size_t)header[0], stdout);
    return fflush(stdout) == 0 ? 0 : 2;
}
