/* Timing and evaluation harness for SymPy's generated Whipple bicycle rhs.
 *
 *   harness bench [runs]   time the rhs over 256 fixed states, print JSON
 *   harness eval           read "q4 q5 q7 u4 u6 u7 T" lines from stdin and
 *                          print "q4' q5' q7' u4' u6' u7'" lines
 *
 * The 256 states are drawn exactly as appell's `bench` command draws its own
 * (SplitMix64 from the same seed; all eight coordinates, the three speeds and
 * the input uniform in [-1, 1); the retained q4, q5, q7 and the speeds form
 * the state), so both programs time the same inputs. Timing: one warm-up
 * pass, then 15 batches of at least 2 ms each, median ns per call; `runs`
 * repeats that and reports every run's median and the median of them.
 * The rhs lives in another translation unit and is called through a
 * volatile function pointer, so nothing is hoisted out of the loop.
 */
#define _POSIX_C_SOURCE 199309L
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

void sympy_whipple_rhs(const double *restrict p, const double *restrict x,
                       const double *restrict r, double *restrict dx);

/* Benchmark bicycle in Moore's parameters, in derive.py's PARAMS order. */
static const double PARAMS[26] = {
    0.35, 0.3, 0.9534570696121849, 0.2676445084476887, 0.03207142672761929,
    0.4707271515135145, -0.47792881146460797, -0.00597083392418685,
    -0.3699518200282974, 85.0, 2.0, 4.0, 3.0, 7.178169776497895, 11.0,
    4.821830223502103, 3.8225535938357873, 0.0603, 0.12, 0.05841337700152972,
    0.06, 0.007586622998470264, 0.009119225261946298, 0.1405, 0.28, 9.81};

#define NSTATES 256
#define NBATCH 15

static uint64_t rng_state;
static uint64_t next_u64(void)
{
    rng_state += 0x9E3779B97F4A7C15ull;
    uint64_t z = rng_state;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}
static double symmetric(void)
{
    double unit = (double)(next_u64() >> 11) / (double)(1ull << 53);
    return 2.0 * unit - 1.0;
}

static double now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double X[NSTATES][6], R[NSTATES][1], DX[6];
static volatile double sink;
static void (*volatile rhs)(const double *restrict, const double *restrict,
                            const double *restrict, double *restrict) = sympy_whipple_rhs;

static void pass(void)
{
    double acc = 0.0;
    for (int s = 0; s < NSTATES; s++) {
        rhs(PARAMS, X[s], R[s], DX);
        acc += DX[3];
    }
    sink = acc;
}

static double time_per_call(void)
{
    double t0 = now_ns();
    pass();
    double once = now_ns() - t0;
    if (once < 1.0) once = 1.0;
    long reps = (long)(2e6 / once) + 1;
    double samples[NBATCH];
    for (int b = 0; b < NBATCH; b++) {
        double start = now_ns();
        for (long k = 0; k < reps; k++) pass();
        samples[b] = (now_ns() - start) / ((double)reps * NSTATES);
    }
    qsort(samples, NBATCH, sizeof(double), cmp_double);
    return samples[NBATCH / 2];
}

int main(int argc, char **argv)
{
    const char *mode = argc > 1 ? argv[1] : "bench";
    if (strcmp(mode, "eval") == 0) {
        double x[6], r[1], dx[6];
        while (scanf("%lf %lf %lf %lf %lf %lf %lf", &x[0], &x[1], &x[2], &x[3], &x[4],
                     &x[5], &r[0]) == 7) {
            sympy_whipple_rhs(PARAMS, x, r, dx);
            printf("%.17g %.17g %.17g %.17g %.17g %.17g\n", dx[0], dx[1], dx[2], dx[3],
                   dx[4], dx[5]);
        }
        return 0;
    }
    if (strcmp(mode, "bench") != 0) {
        fprintf(stderr, "usage: %s [bench [runs] | eval]\n", argv[0]);
        return 2;
    }
    int runs = argc > 2 ? atoi(argv[2]) : 1;
    if (runs < 1) runs = 1;
    rng_state = 0x00A99E115EED2003ull;
    for (int s = 0; s < NSTATES; s++) {
        double q[8], u[3];
        for (int i = 0; i < 8; i++) q[i] = symmetric();
        for (int i = 0; i < 3; i++) u[i] = symmetric();
        R[s][0] = symmetric();
        X[s][0] = q[3]; X[s][1] = q[4]; X[s][2] = q[6];
        X[s][3] = u[0]; X[s][4] = u[1]; X[s][5] = u[2];
    }
    double med[64];
    if (runs > 64) runs = 64;
    for (int k = 0; k < runs; k++) med[k] = time_per_call();
    printf("{\"rhs_ns_runs\": [");
    for (int k = 0; k < runs; k++) printf("%s%.2f", k ? ", " : "", med[k]);
    qsort(med, runs, sizeof(double), cmp_double);
    printf("], \"rhs_ns\": %.2f, \"states\": %d}\n", med[runs / 2], NSTATES);
    return 0;
}
