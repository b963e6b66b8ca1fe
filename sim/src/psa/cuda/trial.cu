/*
 * One PSA trial per thread: the batched `native` kernel (src/psa/batch.rs,
 * `fly`) written out for one network, operation for operation, in double
 * precision. Compiled at run time by NVRTC with --fmad=false for the GPU,
 * and by the host C compiler with -ffp-contract=off for the tests, which
 * hold it to `native` bit for bit without a GPU. Every multiply-add below
 * is an explicit fma() exactly where the Rust code calls mul_add; every
 * other operation is a separately rounded IEEE operation, as in Rust.
 *
 * Plain C (no C++ features), so that both compilers take it.
 *
 * The kernel is specialised at compile time (`cuda::Specialisation` writes
 * the -D options, the same for NVRTC and the host compiler): the loop
 * bounds, the discrete settings and the exponential's polynomial are
 * constants, so that the loops unroll, each thread keeps its network's
 * weights in registers, and the chains of a step's sigmoids overlap.
 *
 *   PSA_HIDDEN            hidden neurons a network of the launch has at most
 *   PSA_NOISY             any noise configured (the batched kernel's NOISY)
 *   PSA_INCREMENTAL       fitness: 1 incremental, 0 original
 *   PSA_SIGNED_SLOWING    the incremental fitness's slowing rule: 1 signed
 *   PSA_HEADING_ABSOLUTE  the heading input: 1 the heading, 0 the error against the target
 *   PSA_HEADING_POSITIVE  its wrap range: 1 [0, 2 pi), 0 (-pi, pi]
 *   PSA_BIAS_NOISE        input noise on the bias too
 *   PSA_NOISE_RAW         input noise on what the sensors measure, before scaling (0: on the scaled inputs)
 *   PSA_FITNESS_SENSED    the fitness reads the sensed state (the inputs over their scales)
 *   PSA_FORCE_SUPPORT, PSA_ARM_SUPPORT   per thruster, which components are kept
 *   PSA_EXP_TERMS, PSA_EXP_Q             the exponential's q, highest first (hex floats)
 *   PSA_LN2_TERMS, PSA_LN2_PARTS         ln 2 in the parts its argument reduction subtracts
 */

#if !defined(PSA_HIDDEN) || !defined(PSA_NOISY) || !defined(PSA_INCREMENTAL) || !defined(PSA_SIGNED_SLOWING) ||     \
    !defined(PSA_HEADING_ABSOLUTE) || !defined(PSA_HEADING_POSITIVE) || !defined(PSA_BIAS_NOISE) ||                 \
    !defined(PSA_NOISE_RAW) || !defined(PSA_FITNESS_SENSED) || !defined(PSA_FORCE_SUPPORT) || !defined(PSA_ARM_SUPPORT) ||                     \
    !defined(PSA_EXP_TERMS) || !defined(PSA_EXP_Q) || !defined(PSA_LN2_TERMS) || !defined(PSA_LN2_PARTS)
#error "trial.cu is compiled with its specialisation's -D options (cuda::Specialisation::defines)"
#endif

/* Threads per block, which __launch_bounds__ promises the compiler. */
#ifndef PSA_BLOCK
#define PSA_BLOCK 128
#endif
/* Blocks an SM is to hold at once, which bounds the registers a thread gets. */
#ifndef PSA_MIN_BLOCKS
#define PSA_MIN_BLOCKS 1
#endif
/* Steps a pass of a trial's loop (the GPU's unrolling; no result depends on it). */
#ifndef PSA_STEP_UNROLL
#define PSA_STEP_UNROLL 1
#endif
#ifdef __CUDACC_RTC__
#define PSA_PRAGMA(x) _Pragma(#x)
#define PSA_UNROLL_STEPS(n) PSA_PRAGMA(unroll n)
#else
#define PSA_UNROLL_STEPS(n)
#endif

#ifdef __CUDACC_RTC__
#define PSA_FN static __device__ __forceinline__
#define PSA_CONST static __constant__ const
#define PSA_UNROLL _Pragma("unroll")
typedef unsigned long long psa_u64;
#define PSA_BITS(x) ((psa_u64)__double_as_longlong(x))
#define PSA_FROM_BITS(u) __longlong_as_double((long long)(u))
#else
#include <math.h>
#include <stdint.h>
#include <string.h>
#define PSA_FN static inline
#define PSA_CONST static const
#define PSA_UNROLL
typedef uint64_t psa_u64;
static inline psa_u64 psa_bits(double x) {
    psa_u64 u;
    memcpy(&u, &x, sizeof u);
    return u;
}
static inline double psa_from_bits(psa_u64 u) {
    double x;
    memcpy(&x, &u, sizeof x);
    return x;
}
#define PSA_BITS(x) psa_bits(x)
#define PSA_FROM_BITS(u) psa_from_bits(u)
#endif

#define PSA_INPUTS 7
#define PSA_THRUSTERS 4
#define PSA_GENES (PSA_INPUTS + PSA_THRUSTERS)

/* Which components of a thruster's force or mount are kept (physics/native.rs, Support). */
#define PSA_SUPPORT_X 0
#define PSA_SUPPORT_Y 1
#define PSA_SUPPORT_BOTH 2

/* The settings every thread shares, passed by value (the kernel's parameter
 * space, read through the constant cache); the Rust side is
 * `cuda::KernelParams` (#[repr(C)]). */
typedef struct {
    double position_scale, velocity_scale, heading_scale, angular_velocity_scale, bias;
    double input_sd, output_sd;
    double box_half_width, heading_window, spin_window, position_points, heading_points;
    double force[PSA_THRUSTERS][2];
    double arm[PSA_THRUSTERS][2];
    double inv_mass, inv_inertia_z, dt;
    int steps;
    int padding;
} PsaParams;

/* One trial's start and target, and its network; the Rust side is
 * `cuda::KernelTrial` (#[repr(C)]). The noise generator's state, where the
 * launch is noisy, lies in an array of its own (4 words a trial). */
typedef struct {
    double position[2], velocity[2], quaternion[2], omega;
    double target[3];
    int network; /* its network's row of PSA_HIDDEN neuron indices */
    int padding;
} PsaTrial;

PSA_CONST double PSA_EXP_COEFFICIENTS[PSA_EXP_TERMS] = {PSA_EXP_Q};
PSA_CONST double PSA_LN2[PSA_LN2_TERMS] = {PSA_LN2_PARTS};
PSA_CONST int PSA_FORCE_SUPPORTS[PSA_THRUSTERS] = {PSA_FORCE_SUPPORT};
PSA_CONST int PSA_ARM_SUPPORTS[PSA_THRUSTERS] = {PSA_ARM_SUPPORT};

#define PSA_PI 3.141592653589793
#define PSA_TAU 6.283185307179586
#define PSA_FRAC_PI_2 1.5707963267948966
#define PSA_FRAC_PI_4 0.7853981633974483
#define PSA_SQRT_2 1.4142135623730951
#define PSA_LOG2_E 1.4426950408889634
#define PSA_TWO_52 4503599627370496.0
#define PSA_ROUNDER 6755399441055744.0
#define PSA_LN2_HI 6.931471803691238e-1
#define PSA_LN2_LO 1.9082149292705877e-10
#define PSA_EXP_LIMIT 708.0
#define PSA_TAN_PI_8 0.41421356237309503
#define PSA_F64_MAX 1.7976931348623157e308
#define PSA_ONE_BITS 0x3FF0000000000000ULL
#define PSA_MANTISSA_BITS 0x000FFFFFFFFFFFFFULL

PSA_CONST double PSA_LN_R[7] = {
    1.4798198605116586e-1, 1.5313837699209373e-1, 1.818357216161805e-1, 2.2222198432149784e-1,
    2.857142874366239e-1,  3.999999999940942e-1,  6.666666666666735e-1,
};
PSA_CONST double PSA_ATAN_S[11] = {
    -1.917688711906226e-2, 3.923165829558719e-2, -5.08544973794026e-2,  5.85814891280221e-2,
    -6.664511447381948e-2, 7.692183190826087e-2, -9.090904578123903e-2, 1.1111111015256361e-1,
    -1.4285714284666542e-1, 1.999999999999552e-1, -3.333333333333333e-1,
};
PSA_CONST double PSA_SIN_QUARTER[9] = {
    6.0669357311061955e-12, -6.688035109811468e-10, 5.692172921967927e-8,  -3.598843235212085e-6,
    1.6044118478735983e-4,  -4.681754135318688e-3,  7.969262624616705e-2, -6.459640975062463e-1,
    PSA_FRAC_PI_2,
};
PSA_CONST double PSA_COS_QUARTER[9] = {
    6.565963114979473e-11, -6.386603083791852e-9, 4.710874778818172e-7,  -2.5202042373060607e-5,
    9.192602748394266e-4,  -2.086348076335296e-2, 2.5366950790104803e-1, -1.2337005501361697,
    1.0,
};

/* esp_neuroevolution::math::horner: acc = acc * x + c, fused. */
PSA_FN double psa_horner(double x, const double *c, int n) {
    double acc = c[0];
    PSA_UNROLL
    for (int i = 1; i < n; i++) acc = fma(acc, x, c[i]);
    return acc;
}

/* esp_neuroevolution::math::exp2_int_of */
PSA_FN double psa_exp2_int(double k) {
    psa_u64 shifted = PSA_BITS(k + (PSA_TWO_52 + 1023.0));
    return PSA_FROM_BITS((shifted - PSA_BITS(PSA_TWO_52)) << 52);
}

/* esp_neuroevolution::math::exp_with, its polynomial and ln 2's parts those of the specialisation */
PSA_FN double psa_exp(double x) {
    if (x < -PSA_EXP_LIMIT) x = -PSA_EXP_LIMIT;
    if (PSA_EXP_LIMIT < x) x = PSA_EXP_LIMIT;
    double k = fma(x, PSA_LOG2_E, PSA_ROUNDER) - PSA_ROUNDER;
    double r = x;
    PSA_UNROLL
    for (int i = 0; i < PSA_LN2_TERMS; i++) r = fma(k, -PSA_LN2[i], r);
    double e_r = 1.0 + fma(r * r, psa_horner(r, PSA_EXP_COEFFICIENTS, PSA_EXP_TERMS), r);
    return e_r * psa_exp2_int(k);
}

/* esp_neuroevolution::math::sigmoid_with */
PSA_FN double psa_sigmoid(double x) { return 1.0 / (1.0 + psa_exp(-x)); }

/* numeric::math::ln, with Real::split_exponent of numeric/mod.rs */
PSA_FN double psa_ln(double x) {
    psa_u64 bits = PSA_BITS(x);
    double mantissa = PSA_FROM_BITS((bits & PSA_MANTISSA_BITS) | PSA_ONE_BITS);
    double exponent = PSA_FROM_BITS((bits >> 52) | PSA_BITS(PSA_TWO_52)) - (PSA_TWO_52 + 1023.0);
    int high = PSA_SQRT_2 < mantissa;
    double m = high ? mantissa * 0.5 : mantissa;
    double e = high ? exponent + 1.0 : exponent;
    double f = m - 1.0;
    double s = f / (2.0 + f);
    double z = s * s;
    double r = z * psa_horner(z, PSA_LN_R, 7);
    double half_f_squared = 0.5 * f * f;
    return e * PSA_LN2_HI - ((half_f_squared - (s * (half_f_squared + r) + e * PSA_LN2_LO)) - f);
}

/* numeric::math::atan2 */
PSA_FN double psa_atan2(double y, double x) {
    double ax = fabs(x), ay = fabs(y);
    int steep = ax < ay;
    double small = steep ? ax : ay, large = steep ? ay : ax;
    int shifted = (large * PSA_TAN_PI_8) < small;
    double numerator = shifted ? small - large : small;
    double denominator = shifted ? small + large : large;
    double t = denominator <= 0.0 ? 0.0 : numerator / denominator;
    double z = t * t;
    double base = shifted ? PSA_FRAC_PI_4 : 0.0;
    double angle = base + fma(t * z, psa_horner(z, PSA_ATAN_S, 11), t);
    angle = steep ? PSA_FRAC_PI_2 - angle : angle;
    angle = x < 0.0 ? PSA_PI - angle : angle;
    return copysign(angle, y);
}

/* numeric::math::fmod and wrap_angle (modulus TAU) */
PSA_FN double psa_wrap_angle(double angle) {
    double a = fabs(angle) < 2.0 * PSA_TAU
                   ? (fabs(angle) < PSA_TAU ? angle : copysign(fabs(angle) - PSA_TAU, angle))
                   : fmod(angle, PSA_TAU);
    a = PSA_PI < a ? a - PSA_TAU : a;
    return a <= -PSA_PI ? a + PSA_TAU : a;
}

/* numeric::math::clamp_unit */
PSA_FN double psa_clamp_unit(double u) {
    u = u < 0.0 ? 0.0 : u;
    return 1.0 < u ? 1.0 : u;
}

/* numeric::normal: xoshiro256++ */
PSA_FN psa_u64 psa_rotl(psa_u64 x, int k) { return (x << k) | (x >> (64 - k)); }
PSA_FN psa_u64 psa_next_word(psa_u64 *s) {
    psa_u64 word = psa_rotl(s[0] + s[3], 23) + s[0];
    psa_u64 t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = psa_rotl(s[3], 45);
    return word;
}

/* numeric::normal::NoiseSource::normal_pair (Box-Muller) */
PSA_FN void psa_normal_pair(psa_u64 *state, double *a, double *b) {
    psa_u64 radial = psa_next_word(state);
    psa_u64 angular = psa_next_word(state);
    double u = 2.0 - PSA_FROM_BITS((radial >> 12) | PSA_ONE_BITS);
    double radius = sqrt(-2.0 * psa_ln(u));
    double f = PSA_FROM_BITS((angular >> 12) | PSA_ONE_BITS) - 1.5;
    double z = f * f;
    double sine = f * psa_horner(z, PSA_SIN_QUARTER, 9);
    double cosine = psa_horner(z, PSA_COS_QUARTER, 9);
    radius = (angular & 1) ? -radius : radius;
    int quarter = (int)((angular >> 1) & 1);
    double x = quarter ? -sine : cosine;
    double y = quarter ? cosine : sine;
    *a = radius * x;
    *b = radius * y;
}

/* NoiseSource::add_scaled */
PSA_FN void psa_add_scaled(psa_u64 *state, double *values, int count, double sd) {
    for (int i = 0; i < count; i += 2) {
        double a, b;
        psa_normal_pair(state, &a, &b);
        values[i] = values[i] + sd * a;
        if (i + 1 < count) values[i + 1] = values[i + 1] + sd * b;
    }
}

/* physics::native::Support::rotate */
PSA_FN void psa_rotate(int support, double r00, double r01, double r10, double r11, double x, double y, double *out) {
    if (support == PSA_SUPPORT_X) {
        out[0] = r00 * x;
        out[1] = r10 * x;
    } else if (support == PSA_SUPPORT_Y) {
        out[0] = r01 * y;
        out[1] = r11 * y;
    } else {
        out[0] = r00 * x + r01 * y;
        out[1] = r10 * x + r11 * y;
    }
}

/* psa::step::sense: the inputs of a state (noisy if configured) and its true heading error. */
PSA_FN void psa_sense(const PsaParams *p, double px, double py, double vx, double vy, double qw, double qz, double omega,
                      double tx, double ty, double th, psa_u64 *noise, double *inputs, double *heading_error) {
    double heading = psa_wrap_angle(2.0 * psa_atan2(qz, qw));
    *heading_error = psa_wrap_angle(heading - th);
    double reading = PSA_HEADING_ABSOLUTE ? psa_wrap_angle(heading) : *heading_error;
    if (PSA_HEADING_POSITIVE && reading < 0.0) reading = reading + PSA_TAU;
    inputs[0] = px - tx;
    inputs[1] = py - ty;
    inputs[2] = vx;
    inputs[3] = vy;
    inputs[4] = reading;
    inputs[5] = omega;
    inputs[6] = p->bias;
    /* psa::sensors::NoiseStage: before scaling (raw) or after it */
    if (PSA_NOISY && PSA_NOISE_RAW && p->input_sd > 0.0)
        psa_add_scaled(noise, inputs, PSA_BIAS_NOISE ? PSA_INPUTS : PSA_INPUTS - 1, p->input_sd);
    inputs[0] = inputs[0] * p->position_scale;
    inputs[1] = inputs[1] * p->position_scale;
    inputs[2] = inputs[2] * p->velocity_scale;
    inputs[3] = inputs[3] * p->velocity_scale;
    inputs[4] = inputs[4] * p->heading_scale;
    inputs[5] = inputs[5] * p->angular_velocity_scale;
    if (PSA_NOISY && !PSA_NOISE_RAW && p->input_sd > 0.0)
        psa_add_scaled(noise, inputs, PSA_BIAS_NOISE ? PSA_INPUTS : PSA_INPUTS - 1, p->input_sd);
}

/* One trial of the network whose genes are `genes` (`active` of its PSA_HIDDEN
 * neurons, the rest unused): its points; *finite says whether the velocity
 * and spin ended finite. */
PSA_FN double psa_fly(const PsaParams *p, const double *genes, int active, const PsaTrial *trial, psa_u64 *noise,
                      int *finite) {
    double px = trial->position[0], py = trial->position[1];
    double vx = trial->velocity[0], vy = trial->velocity[1];
    double qw = trial->quaternion[0], qz = trial->quaternion[1];
    double omega = trial->omega;
    double tx = trial->target[0], ty = trial->target[1], th = trial->target[2];
    double points = 0.0;
    double heading_error;
    double inputs[PSA_INPUTS];
    psa_sense(p, px, py, vx, vy, qw, qz, omega, tx, ty, th, noise, inputs, &heading_error);
    PSA_UNROLL_STEPS(PSA_STEP_UNROLL)
    for (int step = 0; step < p->steps; step++) {
        double out[PSA_THRUSTERS] = {0.0, 0.0, 0.0, 0.0};
        PSA_UNROLL
        for (int k = 0; k < PSA_HIDDEN; k++) {
            if (k < active) {
                const double *w = genes + k * PSA_GENES;
                double activation = w[0] * inputs[0];
                PSA_UNROLL
                for (int i = 1; i < PSA_INPUTS; i++) activation = fma(w[i], inputs[i], activation);
                double h = psa_sigmoid(activation);
                PSA_UNROLL
                for (int o = 0; o < PSA_THRUSTERS; o++) out[o] = fma(h, w[PSA_INPUTS + o], out[o]);
            }
        }
        PSA_UNROLL
        for (int o = 0; o < PSA_THRUSTERS; o++) out[o] = psa_sigmoid(out[o]);
        if (PSA_NOISY && p->output_sd > 0.0) psa_add_scaled(noise, out, PSA_THRUSTERS, p->output_sd);
        PSA_UNROLL
        for (int o = 0; o < PSA_THRUSTERS; o++) out[o] = psa_clamp_unit(out[o]);

        /* PlanarBody::step: accelerate, then the quaternion. */
        double previous_omega = omega;
        double two_qz_qz = 2.0 * qz * qz;
        double one_minus = 1.0 - two_qz_qz;
        double r00 = one_minus, r01 = 2.0 * -(qw * qz), r10 = 2.0 * (qw * qz), r11 = one_minus;
        double fx = 0.0, fy = 0.0, tau = 0.0;
        PSA_UNROLL
        for (int t = 0; t < PSA_THRUSTERS; t++) {
            double wf[2], arm[2];
            double u = out[t];
            psa_rotate(PSA_FORCE_SUPPORTS[t], r00, r01, r10, r11, p->force[t][0] * u, p->force[t][1] * u, wf);
            psa_rotate(PSA_ARM_SUPPORTS[t], r00, r01, r10, r11, p->arm[t][0], p->arm[t][1], arm);
            fx = fx + wf[0];
            fy = fy + wf[1];
            tau = tau + (arm[0] * wf[1] - arm[1] * wf[0]);
        }
        double h = p->dt;
        double h_inv_mass = h * p->inv_mass;
        vx = vx + h_inv_mass * fx;
        vy = vy + h_inv_mass * fy;
        omega = omega + p->inv_inertia_z * (tau * h);
        px = px + h * vx;
        py = py + h * vy;
        double half_w = 0.5 * omega;
        double w = qw + h * (-half_w * qz);
        double z = qz + h * (half_w * qw);
        double inv_norm = 1.0 / sqrt(w * w + z * z);
        qw = w * inv_norm;
        qz = z * inv_norm;

        /* psa::step::score: the true state or the sensed one */
        double next[PSA_INPUTS];
        psa_sense(p, px, py, vx, vy, qw, qz, omega, tx, ty, th, noise, next, &heading_error);
        double ex = px - tx, ey = py - ty, fitness_heading = heading_error, fitness_omega = omega;
        if (PSA_FITNESS_SENSED) {
            ex = next[0] / p->position_scale;
            ey = next[1] / p->position_scale;
            double sensed_heading = next[4] / p->heading_scale;
            fitness_heading = psa_wrap_angle(PSA_HEADING_ABSOLUTE ? sensed_heading - th : sensed_heading);
            fitness_omega = next[5] / p->angular_velocity_scale;
            previous_omega = inputs[5] / p->angular_velocity_scale;
        }
        PSA_UNROLL
        for (int i = 0; i < PSA_INPUTS; i++) inputs[i] = next[i];
        /* FitnessSettings::points */
        int in_box = fabs(ex) < p->box_half_width && fabs(ey) < p->box_half_width;
        int on_heading = fabs(fitness_heading) < p->heading_window;
        double earned;
        if (PSA_INCREMENTAL) {
            double spin = fabs(fitness_omega);
            int slowing = PSA_SIGNED_SLOWING ? fitness_omega < previous_omega : spin < fabs(previous_omega);
            int spin_ok = spin < p->spin_window || slowing;
            double full = on_heading ? p->position_points + p->heading_points : p->position_points;
            earned = in_box && spin_ok ? full : 0.0;
        } else {
            earned = in_box && on_heading ? p->position_points : 0.0;
        }
        points = points + earned;
    }
    *finite = fabs(vx) <= PSA_F64_MAX && fabs(vy) <= PSA_F64_MAX && fabs(omega) <= PSA_F64_MAX;
    return points;
}

/* Trial i of a launch: its network's genes gathered from `neurons` (PSA_GENES
 * a neuron) by its row of `networks` (PSA_HIDDEN neuron indices, the active
 * ones first, -1 after them) into `genes`, its noise state (`noise`, 4 words
 * a trial, read only where the launch is noisy), and its flight. */
PSA_FN void psa_trial(const PsaParams *p, const double *neurons, const int *networks, const PsaTrial *trials,
                      const psa_u64 *noise, int i, double *points, int *finite) {
    const PsaTrial *trial = &trials[i];
    const int *row = networks + (long long)trial->network * PSA_HIDDEN;
    double genes[PSA_HIDDEN * PSA_GENES];
    int active = 0;
    PSA_UNROLL
    for (int k = 0; k < PSA_HIDDEN; k++) {
        int neuron = row[k];
        active = neuron >= 0 ? k + 1 : active;
        PSA_UNROLL
        for (int g = 0; g < PSA_GENES; g++)
            genes[k * PSA_GENES + g] = neuron >= 0 ? neurons[(long long)neuron * PSA_GENES + g] : 0.0;
    }
    psa_u64 state[4] = {0, 0, 0, 0};
    if (PSA_NOISY) {
        PSA_UNROLL
        for (int w = 0; w < 4; w++) state[w] = noise[4 * (long long)i + w];
    }
    points[i] = psa_fly(p, genes, active, trial, state, &finite[i]);
}

#ifdef __CUDACC_RTC__
/* One thread per trial. */
extern "C" __global__ void __launch_bounds__(PSA_BLOCK, PSA_MIN_BLOCKS)
    psa_trials(const PsaParams params, const double *__restrict__ neurons, const int *__restrict__ networks,
               const PsaTrial *__restrict__ trials, const psa_u64 *__restrict__ noise, int count,
               double *__restrict__ points, int *__restrict__ finite) {
    int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < count) psa_trial(&params, neurons, networks, trials, noise, i, points, finite);
}
#else
/* The same trials flown one after another on the host. */
void psa_trials_host(const PsaParams *params, const double *neurons, const int *networks, const PsaTrial *trials,
                     const psa_u64 *noise, int count, double *points, int *finite) {
    for (int i = 0; i < count; i++) psa_trial(params, neurons, networks, trials, noise, i, points, finite);
}
#endif
