/* A minimal FMI 2.0 co-simulation host (ehm's example and test host; plain C, no Python).
 *
 * Loads an unzipped FMU's binary with dlopen, feeds its inputs from a CSV file and writes its outputs to a
 * CSV file, or measures the latency of each communication step.
 *
 *   cc -std=c11 -O2 -I <fmi2 headers> fmu_host.c -o fmu_host -ldl
 *   fmu_host DIR MODEL_IDENTIFIER GUID N_OUTPUTS INPUT.csv OUTPUT.csv
 *   fmu_host DIR MODEL_IDENTIFIER GUID N_OUTPUTS INPUT.csv --bench STEPS
 *
 * DIR: the unzipped FMU (binaries/linux64/MODEL_IDENTIFIER.so, resources/).  INPUT.csv: a header line, then
 * one row per communication step: the step's start time [s] and the values of the inputs (value references
 * 0, 1, ... in column order); the step size is the time to the next row (the last row keeps the one before).
 * OUTPUT.csv: a header line, then the outputs (value references N_INPUTS ... N_INPUTS + N_OUTPUTS - 1) after
 * initialisation and after each step, each row starting with the host's time.  With --bench the input rows
 * are repeated for STEPS steps and the latency of each step (set inputs, fmi2DoStep, get outputs) is printed
 * as "p50_us p99_us max_us mean_us steps".
 */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fmi2Functions.h"

#define MAX_IO 256

static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status, fmi2String category,
                   fmi2String message, ...) {
    va_list ap;
    (void)env;
    fprintf(stderr, "[%s status %d %s] ", instance ? instance : "?", (int)status, category ? category : "");
    va_start(ap, message);
    vfprintf(stderr, message, ap);
    va_end(ap);
    fputc('\n', stderr);
}

static void *load(void *lib, const char *name) {
    void *f = dlsym(lib, name);
    if (!f) {
        fprintf(stderr, "fmu_host: the binary has no %s\n", name);
        exit(3);
    }
    return f;
}

static int compare(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double now_s(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* Rows of numbers after one header line; returns the row count, *ncol the columns. */
static double *read_csv(const char *path, int *nrow, int *ncol) {
    FILE *f = fopen(path, "r");
    char line[65536];
    double *data = NULL;
    int n = 0, cap = 0, cols = -1;
    if (!f || !fgets(line, sizeof line, f)) { fprintf(stderr, "fmu_host: cannot read %s\n", path); exit(2); }
    while (fgets(line, sizeof line, f)) {
        double row[MAX_IO + 1];
        int c = 0;
        char *p = line, *end;
        while (c < MAX_IO + 1) {
            row[c] = strtod(p, &end);
            if (end == p) break;
            c++;
            p = end;
            while (*p == ',' || *p == ' ') p++;
        }
        if (c == 0) continue;
        if (cols < 0) cols = c;
        if (c != cols) { fprintf(stderr, "fmu_host: %s row %d has %d columns, not %d\n", path, n + 2, c, cols); exit(2); }
        if (n == cap) { cap = cap ? 2 * cap : 1024; data = realloc(data, (size_t)cap * cols * sizeof(double)); }
        memcpy(data + (size_t)n * cols, row, cols * sizeof(double));
        n++;
    }
    fclose(f);
    if (n < 2) { fprintf(stderr, "fmu_host: %s needs at least two rows\n", path); exit(2); }
    *nrow = n;
    *ncol = cols;
    return data;
}

#define CALL(what)                                                                  \
    do {                                                                            \
        fmi2Status st_ = (what);                                                    \
        if (st_ > fmi2Warning) {                                                    \
            fprintf(stderr, "fmu_host: %s returned status %d\n", #what, (int)st_);   \
            return 4;                                                               \
        }                                                                           \
    } while (0)

int main(int argc, char **argv) {
    char path[4096], uri[4200];
    void *lib;
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2Component c;
    fmi2ValueReference vin[MAX_IO], vout[MAX_IO];
    double *in, y[MAX_IO], t, h = 0;
    int nrow, ncol, nin, nout, i, j, bench = 0;
    long steps;
    FILE *out = NULL;

    if (argc != 7 && !(argc == 8 && strcmp(argv[6], "--bench") == 0)) {
        fprintf(stderr, "usage: fmu_host DIR MODEL_IDENTIFIER GUID N_OUTPUTS INPUT.csv (OUTPUT.csv | --bench STEPS)\n");
        return 2;
    }
    nout = atoi(argv[4]);
    if (nout < 1 || nout > MAX_IO) { fprintf(stderr, "fmu_host: bad N_OUTPUTS\n"); return 2; }
    in = read_csv(argv[5], &nrow, &ncol);
    nin = ncol - 1;
    bench = argc == 8;
    steps = bench ? atol(argv[7]) : nrow;

    snprintf(path, sizeof path, "%s/binaries/linux64/%s.so", argv[1], argv[2]);
    lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) { fprintf(stderr, "fmu_host: %s\n", dlerror()); return 3; }
    fmi2InstantiateTYPE *instantiate = (fmi2InstantiateTYPE *)load(lib, "fmi2Instantiate");
    fmi2FreeInstanceTYPE *free_instance = (fmi2FreeInstanceTYPE *)load(lib, "fmi2FreeInstance");
    fmi2SetupExperimentTYPE *setup = (fmi2SetupExperimentTYPE *)load(lib, "fmi2SetupExperiment");
    fmi2EnterInitializationModeTYPE *enter = (fmi2EnterInitializationModeTYPE *)load(lib, "fmi2EnterInitializationMode");
    fmi2ExitInitializationModeTYPE *exit_init = (fmi2ExitInitializationModeTYPE *)load(lib, "fmi2ExitInitializationMode");
    fmi2SetRealTYPE *set_real = (fmi2SetRealTYPE *)load(lib, "fmi2SetReal");
    fmi2GetRealTYPE *get_real = (fmi2GetRealTYPE *)load(lib, "fmi2GetReal");
    fmi2DoStepTYPE *do_step = (fmi2DoStepTYPE *)load(lib, "fmi2DoStep");
    fmi2TerminateTYPE *terminate = (fmi2TerminateTYPE *)load(lib, "fmi2Terminate");

    snprintf(uri, sizeof uri, "file://%s/resources", argv[1]);
    c = instantiate("host", fmi2CoSimulation, argv[3], uri, &cb, fmi2False, fmi2False);
    if (!c) { fprintf(stderr, "fmu_host: fmi2Instantiate failed\n"); return 4; }
    for (j = 0; j < nin; j++) vin[j] = (fmi2ValueReference)j;
    for (j = 0; j < nout; j++) vout[j] = (fmi2ValueReference)(nin + j);
    t = in[0];
    CALL(setup(c, fmi2False, 0.0, t, fmi2False, 0.0));
    CALL(enter(c));
    CALL(set_real(c, vin, nin, in + 1));
    CALL(exit_init(c));

    if (!bench) {
        out = fopen(argv[6], "w");
        if (!out) { fprintf(stderr, "fmu_host: cannot write %s\n", argv[6]); return 2; }
        fprintf(out, "time_s");
        for (j = 0; j < nout; j++) fprintf(out, ",vr%u", vout[j]);
        fputc('\n', out);
        CALL(get_real(c, vout, nout, y));
        fprintf(out, "%.17g", t);
        for (j = 0; j < nout; j++) fprintf(out, ",%.17g", y[j]);
        fputc('\n', out);
        for (i = 0; i < nrow; i++) {
            const double *row = in + (size_t)i * ncol;
            if (i + 1 < nrow) h = in[(size_t)(i + 1) * ncol] - row[0];
            CALL(set_real(c, vin, nin, row + 1));
            CALL(do_step(c, row[0], h, fmi2True));
            CALL(get_real(c, vout, nout, y));
            fprintf(out, "%.17g", row[0] + h);
            for (j = 0; j < nout; j++) fprintf(out, ",%.17g", y[j]);
            fputc('\n', out);
        }
        fclose(out);
    } else {
        double *lat = malloc((size_t)steps * sizeof(double)), sum = 0;
        double t0 = in[0];
        h = in[ncol] - in[0];
        for (i = 0; i < steps; i++) {
            const double *row = in + (size_t)(i % nrow) * ncol;
            double start = now_s();
            CALL(set_real(c, vin, nin, row + 1));
            CALL(do_step(c, t0 + i * h, h, fmi2True));
            CALL(get_real(c, vout, nout, y));
            lat[i] = now_s() - start;
            sum += lat[i];
        }
        qsort(lat, (size_t)steps, sizeof(double), compare);
        printf("%.3f %.3f %.3f %.3f %ld\n", 1e6 * lat[steps / 2], 1e6 * lat[(long)(0.99 * (steps - 1))],
               1e6 * lat[steps - 1], 1e6 * sum / steps, steps);
        free(lat);
    }
    CALL(terminate(c));
    free_instance(c);
    dlclose(lib);
    free(in);
    return 0;
}
