/* cg_speed.c: the implicit damping solve's kernels alone, on a sheet of
 * N x N quads (where a contact frame's time goes). CG's operator
 * (cs_system_apply, the pass that takes a third to half of a contact
 * frame) is timed over many calls, best of 5, and a whole solve
 * (cs_cg_solve from rest, tolerance 1e-6 m/s) best of 5; the results'
 * hashes say whether a change to the kernels kept the bits.
 *
 * The sheet is the benchmark's (Table 1 material, bending springs), its
 * vertices jittered by a tenth of an edge so the spring directions are not
 * axis-aligned, all particles free. The step (half_dt) sets how hard the
 * damping couples the particles, so the solve's iterations: 1e-5 is about
 * the 100 x 100 sheet's default step, 1e-4 the damped limit's.
 *
 * usage: bench_cg_speed [N (default 100)] [half_dt (default 1e-4)] [calls (default 500)]
 * Threads: OMP_NUM_THREADS (default one per core). Prints one line. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <xxhash.h>

#include "common/util.h"
#include "sim/internal.h"

/* a fixed pseudo-random sequence in [-0.5, 0.5] */
static double jitter(unsigned *seed)
{
    *seed = *seed * 1103515245u + 12345u;
    return ((*seed >> 8) & 0xffff) / 65535.0 - 0.5;
}

/* XXH3 (64-bit) over the bytes of n doubles: equal hashes, the same bits */
static unsigned long long hash(const double *a, int n)
{
    return (unsigned long long)XXH3_64bits(a, sizeof *a * (size_t)n);
}

int main(int argc, char **argv)
{
    int n = argc > 1 ? atoi(argv[1]) : 100;
    double half_dt = argc > 2 ? atof(argv[2]) : 1e-4;
    int calls = argc > 3 ? atoi(argv[3]) : 500;
    if (n < 2 || n > 2000 || !(half_dt > 0 && half_dt < 1) || calls < 1) {
        fprintf(stderr, "usage: bench_cg_speed [N in 2..2000] [half_dt in (0, 1)] [calls >= 1]\n");
        return 1;
    }
    double size[2] = {1, 1}, rotation[4] = {1, 0, 0, 0}, center[3] = {0, 1, 0};
    int res[2] = {n, n};
    cs_trimesh *mesh = cs_trimesh_create_grid(size, res, rotation, center);
    if (!mesh) {
        fprintf(stderr, "bench_cg_speed: out of memory\n");
        return 1;
    }
    unsigned seed = 5;
    for (int k = 0; k < 3 * mesh->nv; k++)
        mesh->x[k] += 0.1 / n * jitter(&seed);
    cs_cloth_def cloth = {.name = "sheet", .mesh = mesh, .material = cs_default_cloth_material()};
    cs_sim_def def = cs_default_sim_def();
    def.ncloths = 1;
    def.cloths = &cloth;
    def.cg_tolerance = 1e-6;
    char err[256];
    cs_sim *sim = cs_sim_create(&def, err, sizeof err);
    if (!sim) {
        fprintf(stderr, "bench_cg_speed: %s\n", err);
        return 1;
    }
    sim->half_dt = half_dt;
    cs_springs_prepare(&sim->springs, sim->x);
    for (int i = 0; i < sim->n; i++)
        sim->mode[i] = CS_FREE;
    int n3 = 3 * sim->n;
    double *v = malloc(sizeof *v * (size_t)n3), *out = malloc(sizeof *out * (size_t)n3),
           *v0 = calloc((size_t)n3, sizeof *v0), *rhs = malloc(sizeof *rhs * (size_t)n3),
           *sol = malloc(sizeof *sol * (size_t)n3), *force = malloc(sizeof *force * (size_t)n3);
    if (!v || !out || !v0 || !rhs || !sol || !force) {
        fprintf(stderr, "bench_cg_speed: out of memory\n");
        return 1;
    }
    for (int k = 0; k < n3; k++) {
        v[k] = jitter(&seed);
        rhs[k] = 1e-5 * jitter(&seed);
    }

    double apply = INFINITY, solve = INFINITY, elastic = INFINITY;
    int iterations = 0;
    for (int rep = 0; rep < 5; rep++) {
        double t0 = cs_now();
        for (int c = 0; c < calls; c++)
            cs_system_apply(sim, v, out);
        apply = fmin(apply, (cs_now() - t0) / calls);
        t0 = cs_now(); /* the springs' pass each B.1 and B.5 makes first */
        for (int c = 0; c < calls; c++)
            cs_springs_elastic(&sim->springs, sim->x, force);
        elastic = fmin(elastic, (cs_now() - t0) / calls);
        t0 = cs_now();
        iterations = cs_cg_solve(sim, v0, rhs, sol, NULL, NULL, NULL, -1);
        solve = fmin(solve, cs_now() - t0);
    }
    long entries = sim->springs.row_start[sim->springs.nrows];
    printf("quads %d particles %d row_entries %ld threads %d half_dt %g: operator %.1f us "
           "(%.2f ns per entry), elastic forces %.1f us, solve %d iterations %.1f us each, hashes "
           "%016llx %016llx %016llx\n",
           n, sim->n, entries, omp_get_max_threads(), half_dt, 1e6 * apply,
           1e9 * apply / (double)entries, 1e6 * elastic, iterations,
           1e6 * solve / (iterations ? iterations : 1), hash(out, n3), hash(sol, n3),
           hash(force, n3));
    free(v);
    free(out);
    free(v0);
    free(rhs);
    free(sol);
    free(force);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
    return 0;
}
