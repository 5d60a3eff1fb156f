/* stream_triad.c: the machine's memory bandwidth as STREAM's triad
 * a[i] = b[i] + s c[i] measures it (McCalpin), with OpenMP threads, on
 * arrays far larger than the caches. Prints "triad_GBps <best of 10>"
 * counting 24 bytes per element (two reads, one write; write-allocate
 * traffic not counted, as STREAM does). bench/speed.py runs it beside the
 * simulation to say how far the time step is from the hardware's limit.
 * usage: bench_stream_triad [MiB per array, default 256] */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int main(int argc, char **argv)
{
    long mib = argc > 1 ? atol(argv[1]) : 256;
    if (mib < 1 || mib > 65536) {
        fprintf(stderr, "bench_stream_triad: MiB per array must be 1..65536\n");
        return 1;
    }
    long n = mib * 1024 * 1024 / (long)sizeof(double);
    double *a = malloc(sizeof *a * (size_t)n), *b = malloc(sizeof *b * (size_t)n),
           *c = malloc(sizeof *c * (size_t)n);
    if (!a || !b || !c) {
        fprintf(stderr, "bench_stream_triad: out of memory\n");
        return 1;
    }
#pragma omp parallel for schedule(static)
    for (long i = 0; i < n; i++) { /* first touch by the threads that use them */
        a[i] = 0;
        b[i] = 1;
        c[i] = 2;
    }
    double best = 0, s = 3;
    for (int rep = 0; rep < 10; rep++) {
        double t0 = now();
#pragma omp parallel for schedule(static)
        for (long i = 0; i < n; i++)
            a[i] = b[i] + s * c[i];
        double gbps = 24.0 * (double)n / (now() - t0) / 1e9;
        if (gbps > best)
            best = gbps;
    }
    printf("triad_GBps %.2f threads %d check %g\n", best, omp_get_max_threads(), a[n / 2]);
    free(a);
    free(b);
    free(c);
    return 0;
}
