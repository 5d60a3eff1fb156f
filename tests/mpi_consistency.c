/* mpi_consistency.c: Section 7 under mpirun (-np 1, 2 and 4 from ctest).
 *
 * Each case runs a scene on all ranks (MPI_COMM_WORLD) and, on rank 0, the
 * same scene alone (MPI_COMM_SELF, one rank, no messages) as the reference:
 *  - self-collision off: every frame's positions within ROUNDOFF_BOUND of
 *    the reference (both friction methods, see ROUNDOFF_BOUND), the same
 *    CG iteration count per frame (the stopping
 *    test is a maximum, exact at any rank count), and one rank bit
 *    identical;
 *  - self-collision on: zero intersecting triangle pairs (the independent
 *    verifier) at every frame end at every rank count, collisions and
 *    impact zones (spanning ranks where sheets meet across the partition),
 *    and the centre of mass within CENTRE_BOUND of the reference's, except
 *    for the twisted strip: it buckles one way or the other on round-off
 *    (without self-collision too, 1 and 2 ranks differ by 2e-16 m after
 *    one frame, 3e-12 after two, 6e-5 after three), a bifurcation no
 *    implementation can pin down;
 *  - the partition: a median split gives balanced, spatially separated
 *    parts, and every rank's ghost lists match its neighbours'.
 * Not a cmocka program: failures are counted on every rank and summed, and
 * the exit status says whether any rank failed. */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <mpi.h>

#include "import/import.h"
#include "sim/internal.h"
#include "sim/par.h"

/* Dot products summed in another order differ in the last bits; over the
 * drape below that grows to ~1e-12 m (8e-13 on 2 ranks, with contact). A
 * real bug (a missing ghost, a spring counted twice) moves particles by
 * millimetres. The previous friction method (projection) carries CG's
 * round-off straight into the new velocity (v^(n+1) = 2 v_P - v*, where the
 * improved method recomputes v_NP from the forces, so the solve's round-off
 * enters only through h/m D v_P). Measured on the 24 x 24 drape over 10
 * frames: its difference starts at frame 2 in free fall (1e-18 m, against
 * frame 5 for the improved method), reaches 3e-9 m on 2 ranks, and on 4
 * ranks a solve near its stopping test takes one iteration fewer (540
 * against 541): that solve's residual (cg_tolerance, 1e-3 m/s at most,
 * times a step of 3e-4 s) stays in the projection method's velocity, 2e-6
 * m. Neither is a missing term, so the projection method is held to the
 * solver's tolerance (iteration counts within one per frame, positions
 * within 1e-5 m), two orders below a real bug. */
#define ROUNDOFF_BOUND 1e-9
#define TOLERANCE_BOUND_PROJECTION 1e-5
#define CENTRE_BOUND 2e-3

static int failures;
static int world_rank, world_size;

#define CHECK(cond, ...)                                                      \
    do {                                                                      \
        if (!(cond)) {                                                        \
            failures++;                                                       \
            fprintf(stderr, "rank %d: %s:%d: ", world_rank, __FILE__, __LINE__); \
            fprintf(stderr, __VA_ARGS__);                                     \
            fputc('\n', stderr);                                              \
        }                                                                     \
    } while (0)

static cs_scene *load(const char *name, int noverrides, const char *const *overrides)
{
    char path[1024], err[1024];
    snprintf(path, sizeof path, "%s/scenes/%s", CS_SOURCE_DIR, name);
    cs_scene *scene = NULL;
    if (cs_scene_load(path, noverrides, overrides, &scene, err, sizeof err) != CS_OK) {
        fprintf(stderr, "rank %d: cannot load %s: %s\n", world_rank, path, err);
        MPI_Abort(MPI_COMM_WORLD, 2);
    }
    return scene;
}

typedef struct trajectory {
    int frames, n;
    double *x;          /* frames+1 states of 3 n */
    long *cg;           /* CG iterations per frame */
    long *intersections;
    double *centre;     /* 3 per frame */
    long collisions, zones, zones_across; /* zones_across: rigid moves spanning ranks */
    long contacts;      /* body contacts over all frames */
} trajectory;

static void trajectory_free(trajectory *t)
{
    free(t->x);
    free(t->cg);
    free(t->intersections);
    free(t->centre);
}

/* Runs the scene on comm; rank 0 of comm records everything. */
static trajectory run(const cs_scene *scene, MPI_Comm comm, int frames)
{
    cs_sim_def def = scene->def;
    def.comm = MPI_Comm_c2f(comm);
    char err[512];
    cs_sim *sim = cs_sim_create(&def, err, sizeof err);
    if (!sim) {
        fprintf(stderr, "rank %d: %s\n", world_rank, err);
        MPI_Abort(MPI_COMM_WORLD, 2);
    }
    trajectory t = {.frames = frames, .n = cs_sim_particle_count(sim)};
    t.x = calloc((size_t)(frames + 1) * 3 * (size_t)t.n, sizeof *t.x);
    t.cg = calloc((size_t)frames + 1, sizeof *t.cg);
    t.intersections = calloc((size_t)frames + 1, sizeof *t.intersections);
    t.centre = calloc(3 * ((size_t)frames + 1), sizeof *t.centre);
    const double *m = cs_sim_masses(sim);
    int comm_rank;
    MPI_Comm_rank(comm, &comm_rank);
    for (int f = 0; f <= frames; f++) {
        cs_frame_stats stats = {0};
        if (f > 0) {
            int rc = cs_sim_advance_frame(sim, &stats);
            CHECK(rc == CS_OK, "frame %d: status %d", f, rc);
        }
        t.cg[f] = stats.cg_iterations;
        t.contacts += stats.body_contacts;
        /* the independent verifier, whatever the scene asks for: rank 0
         * holds every position after a frame */
        if (comm_rank == 0)
            t.intersections[f] = cs_sim_count_intersections(sim);
        t.collisions += stats.collisions;
        t.zones += stats.impact_zones;
        const double *x = cs_sim_positions(sim);
        memcpy(t.x + (size_t)f * 3 * t.n, x, sizeof *x * 3 * (size_t)t.n);
        double M = 0;
        for (int i = 0; i < t.n; i++) {
            M += m[i];
            for (int d = 0; d < 3; d++)
                t.centre[3 * f + d] += m[i] * x[3 * i + d];
        }
        for (int d = 0; d < 3; d++)
            t.centre[3 * f + d] /= M;
    }
    if (sim->selfcol)
        t.zones_across = sim->selfcol->stats.zones_across;
    cs_sim_destroy(sim);
    return t;
}

/* A barrier whose waiters sleep: MPI_Barrier polls, so while rank 0 runs
 * the reference alone the other ranks would take the cores it needs (ctest
 * runs 4 ranks on 2 cores). */
static void sleeping_barrier(void)
{
    MPI_Request request;
    MPI_Ibarrier(MPI_COMM_WORLD, &request);
    int done = 0;
    while (MPI_Test(&request, &done, MPI_STATUS_IGNORE), !done)
        nanosleep(&(struct timespec){.tv_nsec = 2000000}, NULL);
}

static trajectory reference(const cs_scene *scene, int frames)
{
    trajectory ref = {0};
    if (world_rank == 0)
        ref = run(scene, MPI_COMM_SELF, frames);
    sleeping_barrier();
    return ref;
}

/* The drape past its landing: free fall, then the ball and the ground in
 * contact with CG at work (the first frames alone would compare 0 CG
 * iterations with 0), under both friction methods. */
static void test_same_frames_without_self_collision(const char *friction)
{
    enum { FRAMES = 6 };
    bool projection = strcmp(friction, "projection") == 0;
    char method[64];
    snprintf(method, sizeof method, "effects.friction=%s", friction);
    /* lowered so that it lands in frame 3 */
    const char *ov[] = {"cloths.0.grid.resolution=[20,20]", "cloths.0.grid.center=[0,0.8,0]",
                        "time.frames=6", method};
    cs_scene *scene = load("drape.yaml", 4, ov);
    trajectory ref = reference(scene, FRAMES);
    trajectory par = run(scene, MPI_COMM_WORLD, FRAMES);
    if (world_rank == 0) {
        double worst = 0;
        long cg = 0;
        for (int f = 0; f <= FRAMES; f++) {
            for (int k = 0; k < 3 * par.n; k++)
                worst = fmax(worst, fabs(par.x[(size_t)f * 3 * par.n + k] -
                                         ref.x[(size_t)f * 3 * par.n + k]));
            CHECK(projection ? labs(par.cg[f] - ref.cg[f]) <= 1 : par.cg[f] == ref.cg[f],
                  "%s frame %d: %ld CG iterations vs %ld on one rank", friction, f, par.cg[f],
                  ref.cg[f]);
            CHECK(par.intersections[f] == 0, "%s frame %d: %ld intersecting pairs", friction, f,
                  par.intersections[f]);
            cg += par.cg[f];
        }
        double bound = projection ? TOLERANCE_BOUND_PROJECTION : ROUNDOFF_BOUND;
        printf("drape (%s friction), %d rank%s: largest difference from one rank %.3g m "
               "(bound %g), %ld body contacts, %ld CG iterations\n", friction, world_size,
               world_size == 1 ? "" : "s", worst, bound, par.contacts, cg);
        CHECK(worst <= bound, "%s: positions differ by %g m", friction, worst);
        if (world_size == 1)
            CHECK(worst == 0, "one rank is not bit identical: %g", worst);
        /* the comparison means something: the sheet fell onto the ball */
        double moved = fabs(par.centre[3 * FRAMES + 1] - par.centre[1]);
        CHECK(moved > 0.05, "the sheet fell only %g m", moved);
        CHECK(par.contacts > 0 && cg > 0, "%s: %ld contacts and %ld CG iterations to compare",
              friction, par.contacts, cg);
        CHECK(par.contacts == ref.contacts, "%s: %ld contacts vs %ld on one rank", friction,
              par.contacts, ref.contacts);
    }
    trajectory_free(&ref);
    trajectory_free(&par);
    cs_scene_destroy(scene);
}

/* centre_bound < 0: the motion is a bifurcation (the twisted strip buckles
 * one way or the other on round-off), so only the invariant is compared */
static void test_collision_free_with_self_collision(const char *name, int frames,
                                                    int noverrides, const char *const *ov,
                                                    double centre_bound, bool want_across)
{
    cs_scene *scene = load(name, noverrides, ov);
    trajectory ref = reference(scene, frames);
    trajectory par = run(scene, MPI_COMM_WORLD, frames);
    if (world_rank == 0) {
        double worst = 0;
        for (int f = 1; f <= frames; f++) {
            CHECK(par.intersections[f] == 0, "%s frame %d: %ld intersecting pairs", name, f,
                  par.intersections[f]);
            CHECK(ref.intersections[f] == 0, "%s frame %d: reference has %ld", name, f,
                  ref.intersections[f]);
            for (int d = 0; d < 3; d++)
                worst = fmax(worst, fabs(par.centre[3 * f + d] - ref.centre[3 * f + d]));
        }
        printf("%s, %d rank%s: %ld collisions, %ld impact zones (%ld across ranks), centre of "
               "mass within %.3g m of one rank's\n", name, world_size,
               world_size == 1 ? "" : "s", par.collisions, par.zones, par.zones_across, worst);
        if (centre_bound > 0)
            CHECK(worst <= centre_bound, "%s: centre of mass off by %g m", name, worst);
        /* both scenes reach step C's last resort; the falling sheets meet
         * across the partition, so their zones span ranks */
        CHECK(par.collisions > 0 && par.zones > 0, "%s: no collisions or zones to test", name);
        if (want_across && world_size > 1)
            CHECK(par.zones_across > 0, "%s: no impact zone spans two ranks", name);
    }
    trajectory_free(&ref);
    trajectory_free(&par);
    cs_scene_destroy(scene);
}

static void test_partition(void)
{
    /* a 40 x 10 grid split into 1..7 parts: sizes within one of n/parts
     * at each level, and each part a slab along the long axis */
    int nx = 40, ny = 10, n = nx * ny;
    double *x = calloc(3 * (size_t)n, sizeof *x);
    int *owner = calloc((size_t)n, sizeof *owner);
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++) {
            x[3 * (j * nx + i)] = i;
            x[3 * (j * nx + i) + 2] = j;
        }
    for (int parts = 1; parts <= 7; parts++) {
        cs_par_median_split(n, x, parts, owner);
        int count[8] = {0};
        for (int i = 0; i < n; i++) {
            CHECK(owner[i] >= 0 && owner[i] < parts, "owner %d of %d parts", owner[i], parts);
            count[owner[i]]++;
        }
        for (int r = 0; r < parts; r++)
            CHECK(abs(count[r] - n / parts) <= parts, "%d parts: part %d has %d of %d", parts,
                  r, count[r], n);
        if (parts == 2) /* the median plane across the long axis */
            for (int i = 0; i < n; i++)
                CHECK(owner[i] == (x[3 * i] >= 20), "2 parts: particle %d on the wrong side", i);
    }
    free(x);
    free(owner);

    /* the halo of a real simulation: what a rank sends a neighbour is what
     * that neighbour expects, particle for particle */
    const char *ov[] = {"cloths.0.grid.resolution=[12,12]"};
    cs_scene *scene = load("drape.yaml", 1, ov);
    cs_sim *sim = cs_sim_create(&scene->def, NULL, 0);
    CHECK(sim != NULL, "no simulation");
    const cs_par *p = sim->par;
    CHECK(p->size == world_size, "%d ranks in the partition", p->size);
    for (int l = 0; l < p->ghosts.nlinks; l++) {
        const cs_halo_link *k = p->ghosts.link + l;
        int sizes[2] = {k->nsend, k->nrecv}, theirs[2];
        MPI_Sendrecv(sizes, 2, MPI_INT, k->rank, 1, theirs, 2, MPI_INT, k->rank, 1,
                     MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        CHECK(theirs[0] == k->nrecv && theirs[1] == k->nsend, "halo sizes disagree with %d",
              k->rank);
        int *recv = malloc(sizeof *recv * ((size_t)theirs[0] + 1));
        MPI_Sendrecv(k->send, k->nsend, MPI_INT, k->rank, 2, recv, theirs[0], MPI_INT, k->rank,
                     2, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        for (int j = 0; j < k->nrecv && theirs[0] == k->nrecv; j++) {
            CHECK(recv[j] == k->recv[j], "ghost %d from rank %d: %d vs %d", j, k->rank,
                  recv[j], k->recv[j]);
            CHECK(p->owner[k->recv[j]] == k->rank, "a ghost not owned by its sender");
        }
        for (int j = 0; j < k->nsend; j++)
            CHECK(p->owner[k->send[j]] == p->rank, "sending a particle not owned here");
        free(recv);
    }
    /* neighbours only: a 12 x 12 sheet over 4 ranks has no rank talking
     * to all others' ghosts through the time integration */
    CHECK(p->ghosts.nlinks <= (world_size > 1 ? world_size - 1 : 0), "%d links",
          p->ghosts.nlinks);
    cs_sim_destroy(sim);
    cs_scene_destroy(scene);
}

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &world_rank);
    MPI_Comm_size(MPI_COMM_WORLD, &world_size);

    test_partition();
    test_same_frames_without_self_collision("improved");
    test_same_frames_without_self_collision("projection");
    /* step C settles the stack's collisions within its default 8 passes
     * (since step C's pairs carry their history), so zones come from one
     * pass: the zones must still span ranks */
    const char *stack[] = {"time.frames=8", "self_collision.zone_iterations=1"};
    test_collision_free_with_self_collision("stack.yaml", 8, 2, stack, CENTRE_BOUND, true);
    /* step A's other broad phase: its boxes come from every particle's
     * velocity, gathered to every rank, so ranks find the same pairs */
    const char *stack_path[] = {"time.frames=8", "self_collision.zone_iterations=1",
                                "self_collision.pruning=path"};
    test_collision_free_with_self_collision("stack.yaml", 8, 3, stack_path, CENTRE_BOUND, true);
    /* the strip knots onto itself; repulsions too thin to stop it, so step
     * C's collisions and impact zones (early: after one pass, as for the
     * stack; whether a second pass settles the knot's collisions turns on
     * round-off and the solver's start) do the work, across ranks */
    const char *twist[] = {"cloths.0.grid.resolution=[40,10]", "time.frames=26",
                           "self_collision.thickness=0.00001", "self_collision.zone_iterations=1"};
    test_collision_free_with_self_collision("twist.yaml", 26, 4, twist, -1, false);

    int total = 0;
    MPI_Allreduce(&failures, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
    if (world_rank == 0)
        printf("%s: %d failure%s on %d rank%s\n", total ? "FAILED" : "passed", total,
               total == 1 ? "" : "s", world_size, world_size == 1 ? "" : "s");
    MPI_Finalize();
    return total ? 1 : 0;
}
