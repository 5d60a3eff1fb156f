/* levelset_speed.c: what mesh bodies cost, for docs/performance.md; a
 * benchmark, never a timed test.
 *
 *   bench_levelset_speed [ASSETS_DIR]
 *
 * 1. Conversion: a UV sphere of radius 1 with 100k triangles (and the
 *    Stanford bunny, 69k triangles, scaled to 1 m, when ASSETS_DIR holds
 *    it) at two voxel sizes, with a narrow band inside and with the
 *    interior filled: seconds, active voxels, grid memory, peak resident
 *    memory.
 * 2. Queries: phi and grad phi of the grid against the analytic sphere, per
 *    query, at points near the surface.
 * 3. In the simulation: the body_collision and body_friction stages per
 *    cloth point per step, a 40 x 40 sheet resting on the sphere, grid body
 *    against analytic body; and the body stages with 48 spheres of which
 *    one is under the cloth, against that one alone (the partition).
 * Every time is the median of 3 runs.
 */
#include "import/import.h"
#include "sim/sim.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double median3(double a, double b, double c)
{
    if (a > b) {
        double t = a;
        a = b;
        b = t;
    }
    if (b > c)
        b = c;
    return a > b ? a : b;
}

/* A UV sphere with about ntri triangles. */
static cs_trimesh *uv_sphere(double r, int ntri)
{
    int stacks = (int)sqrt(ntri / 4.0), slices = 2 * stacks;
    int nv = 2 + (stacks - 1) * slices, nt = 2 * slices * (stacks - 1);
    cs_trimesh *m = cs_trimesh_create(nv, nt);
    int v = 0, t = 0;
    m->x[3 * v + 1] = r, v++;
    for (int i = 1; i < stacks; i++)
        for (int j = 0; j < slices; j++, v++) {
            double th = M_PI * i / stacks, ph = 2 * M_PI * j / slices;
            m->x[3 * v] = r * sin(th) * cos(ph);
            m->x[3 * v + 1] = r * cos(th);
            m->x[3 * v + 2] = r * sin(th) * sin(ph);
        }
    m->x[3 * v + 1] = -r, v++;
    int south = v - 1;
#define TRI(a, b, c) (m->tri[3 * t] = (a), m->tri[3 * t + 1] = (b), m->tri[3 * t + 2] = (c), t++)
    for (int j = 0; j < slices; j++) {
        int j1 = (j + 1) % slices;
        TRI(0, 1 + j1, 1 + j);
        int last = 1 + (stacks - 2) * slices;
        TRI(south, last + j, last + j1);
    }
    for (int i = 1; i < stacks - 1; i++)
        for (int j = 0; j < slices; j++) {
            int j1 = (j + 1) % slices;
            int a = 1 + (i - 1) * slices + j, b = 1 + (i - 1) * slices + j1;
            int c = 1 + i * slices + j, d = 1 + i * slices + j1;
            TRI(a, b, d);
            TRI(a, d, c);
        }
#undef TRI
    m->nt = t;
    return m;
}

/* One conversion in a child process, so that its peak resident memory is
 * its own (the parent holds only the meshes): seconds, grid info and the
 * peak come back through a pipe. */
typedef struct conversion {
    double seconds;
    cs_levelset_info info;
    double peak_mb;
} conversion;

static conversion convert_once(const cs_trimesh *mesh, double voxel, bool fill)
{
    conversion c;
    memset(&c, 0, sizeof c);
    int fd[2];
    if (pipe(fd) != 0)
        exit(1);
    pid_t pid = fork();
    if (pid == 0) {
        char err[256];
        close(fd[0]);
        double t0 = now();
        cs_levelset *ls = cs_levelset_create(mesh, voxel, 3, fill, err, sizeof err);
        c.seconds = now() - t0;
        if (!ls) {
            fprintf(stderr, "%s\n", err);
            _exit(1);
        }
        cs_levelset_get_info(ls, &c.info);
        struct rusage ru;
        getrusage(RUSAGE_SELF, &ru);
        c.peak_mb = ru.ru_maxrss / 1024.0;
        if (write(fd[1], &c, sizeof c) != (ssize_t)sizeof c)
            _exit(1);
        _exit(0);
    }
    close(fd[1]);
    int status;
    bool ok = read(fd[0], &c, sizeof c) == (ssize_t)sizeof c;
    close(fd[0]);
    if (waitpid(pid, &status, 0) != pid || !ok || status != 0)
        exit(1);
    return c;
}

static void convert(const char *what, const cs_trimesh *mesh, double voxel, bool fill)
{
    conversion c[3];
    for (int run = 0; run < 3; run++)
        c[run] = convert_once(mesh, voxel, fill);
    printf("| %s | %d | %g | %s | %.2f | %.3g | %.1f | %.0f |\n", what, mesh->nt, voxel,
           fill ? "filled" : "band 3", median3(c[0].seconds, c[1].seconds, c[2].seconds),
           (double)c[0].info.active_voxels, c[0].info.memory_bytes / 1e6,
           median3(c[0].peak_mb, c[1].peak_mb, c[2].peak_mb));
    fflush(stdout);
}

static double sphere_phi(const void *data, const double p[3], double g[3])
{
    double r = *(const double *)data, n = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    for (int k = 0; k < 3; k++)
        g[k] = p[k] / n;
    return n - r;
}

static void queries(const cs_trimesh *sphere, double voxel)
{
    char err[256];
    cs_levelset *ls = cs_levelset_create(sphere, voxel, 3, true, err, sizeof err);
    int n = 1000000;
    double *p = malloc(3 * (size_t)n * sizeof *p);
    srand(7);
    /* points within 2 voxels of the surface, in a coherent order (sorted by
     * angle, as cloth points near each other are queried one after another) */
    for (int i = 0; i < n; i++) {
        double th = M_PI * (i / 1000) / 1000.0, ph = 2 * M_PI * (i % 1000) / 1000.0;
        double r = 1 + voxel * (4.0 * rand() / RAND_MAX - 2.0);
        p[3 * i] = r * sin(th) * cos(ph);
        p[3 * i + 1] = r * cos(th);
        p[3 * i + 2] = r * sin(th) * sin(ph);
    }
    double grid[3], exact[3], one = 1, sink = 0, g[3];
    for (int run = 0; run < 3; run++) {
        double t0 = now();
        for (int i = 0; i < n; i++)
            sink += cs_levelset_phi(ls, p + 3 * i, g);
        grid[run] = (now() - t0) / n;
        t0 = now();
        for (int i = 0; i < n; i++)
            sink += sphere_phi(&one, p + 3 * i, g);
        exact[run] = (now() - t0) / n;
    }
    printf("| phi + grad phi query, grid (voxel %g) | %.0f ns |\n", voxel,
           1e9 * median3(grid[0], grid[1], grid[2]));
    printf("| phi + grad phi query, analytic sphere | %.0f ns |\n",
           1e9 * median3(exact[0], exact[1], exact[2]));
    if (sink == 12345.678)
        printf("(%g)\n", sink);
    free(p);
    cs_levelset_destroy(ls);
}

/* Body stages per cloth point per step: a 40 x 40 sheet dropped on a body,
 * timed over 60 steps once it rests on it. */
static double body_cost(const cs_body_def *bodies, int nbodies)
{
    double res[3];
    for (int run = 0; run < 3; run++) {
        double size[2] = {1.6, 1.6}, rot[4] = {1, 0, 0, 0}, centre[3] = {0, 1.05, 0};
        int grid[2] = {40, 40};
        cs_trimesh *cloth = cs_trimesh_create_grid(size, grid, rot, centre);
        cs_sim_def def = cs_default_sim_def();
        cs_cloth_def cd = {.name = "sheet", .mesh = cloth, .material = cs_default_cloth_material()};
        cd.material.density = 0.15;
        def.cloths = &cd;
        def.ncloths = 1;
        def.bodies = bodies;
        def.nbodies = nbodies;
        char err[256];
        cs_sim *sim = cs_sim_create(&def, err, sizeof err);
        if (!sim) {
            fprintf(stderr, "%s\n", err);
            exit(1);
        }
        cs_frame_stats st;
        for (int f = 0; f < 6; f++) /* 0.25 s: the sheet lands */
            cs_sim_advance_frame(sim, &st);
        const cs_stage_timing *t = cs_sim_stage_timing(sim);
        double s0 = t[CS_STAGE_BODY_COLLISION].seconds + t[CS_STAGE_BODY_FRICTION].seconds;
        for (int k = 0; k < 60; k++)
            cs_sim_step(sim, cs_sim_dt(sim));
        double s1 = t[CS_STAGE_BODY_COLLISION].seconds + t[CS_STAGE_BODY_FRICTION].seconds;
        res[run] = (s1 - s0) / 60 / cs_sim_particle_count(sim);
        cs_sim_destroy(sim);
        cs_trimesh_destroy(cloth);
    }
    return median3(res[0], res[1], res[2]);
}

int main(int argc, char **argv)
{
    const char *assets = argc > 1 ? argv[1] : CS_SOURCE_DIR "/assets";
    cs_trimesh *sphere = uv_sphere(1.0, 100000);

    printf("## Conversion (median of 3; band 3 voxels; peak RSS of the converting process)\n\n");
    printf("| mesh | triangles | voxel (m) | interior | seconds | active voxels | grid MB | "
           "peak RSS MB |\n");
    printf("|---|---|---|---|---|---|---|---|\n");
    for (int fill = 0; fill < 2; fill++) {
        convert("UV sphere r = 1 m", sphere, 0.01, fill);
        convert("UV sphere r = 1 m", sphere, 0.005, fill);
    }
    char path[1024], err[512];
    snprintf(path, sizeof path, "%s/stanford-bunny.obj", assets);
    cs_mesh_placement pl = cs_default_mesh_placement();
    pl.scale[0] = pl.scale[1] = pl.scale[2] = 1.0 / 0.156; /* 1 m long */
    cs_trimesh *bunny = NULL;
    if (cs_mesh_import(path, &pl, &bunny, NULL, err, sizeof err) == CS_OK &&
        cs_mesh_close_holes(&bunny) >= 0) {
        for (int fill = 0; fill < 2; fill++) {
            convert("Stanford bunny, 1 m long", bunny, 0.01, fill);
            convert("Stanford bunny, 1 m long", bunny, 0.005, fill);
        }
    } else {
        printf("(bunny skipped: %s)\n", err);
    }
    cs_trimesh_destroy(bunny);

    printf("\n## Queries (median of 3 x 1M points within 2 voxels of the surface)\n\n");
    printf("| query | time |\n|---|---|\n");
    queries(sphere, 0.01);

    printf("\n## Body stages per cloth point per step (40 x 40 sheet resting on a sphere r = 0.5 m)\n\n");
    char e2[256];
    cs_trimesh *small = uv_sphere(0.5, 100000);
    cs_levelset *ls = cs_levelset_create(small, 0.01, 3, true, e2, sizeof e2);
    cs_body_def analytic = cs_default_body_def();
    analytic.shape = CS_BODY_SPHERE;
    analytic.radius = 0.5;
    analytic.friction = 0.5;
    analytic.motion.position[1] = 0.5;
    cs_body_def grid = analytic;
    grid.shape = CS_BODY_MESH;
    cs_levelset_attach(&grid, ls);
    printf("| body | seconds per point per step |\n|---|---|\n");
    printf("| analytic sphere | %.0f ns |\n", 1e9 * body_cost(&analytic, 1));
    printf("| level-set sphere (100k triangles, voxel 0.01 m) | %.0f ns |\n",
           1e9 * body_cost(&grid, 1));
    /* 48 spheres on a 7 x 7 lattice (one cell empty), one under the cloth */
    cs_body_def many[48];
    int nb = 0;
    for (int i = 0; i < 7; i++)
        for (int j = 0; j < 7 && nb < 48; j++) {
            if (i == 3 && j == 3)
                continue;
            many[nb] = analytic;
            many[nb].radius = 0.3;
            many[nb].motion.position[0] = 4.0 * (i - 3);
            many[nb].motion.position[2] = 4.0 * (j - 3);
            many[nb].motion.position[1] = 0.3;
            nb++;
        }
    many[0] = analytic; /* under the cloth */
    printf("| 1 analytic sphere under the cloth, 47 others away | %.0f ns |\n",
           1e9 * body_cost(many, nb));
    cs_levelset_destroy(ls);
    cs_trimesh_destroy(small);
    cs_trimesh_destroy(sphere);
    return 0;
}
