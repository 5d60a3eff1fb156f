/* Self-collisions (Sections 4 and 5): the coplanarity cubic, impact zones,
 * and the hard cases, each run through a scene and checked at every frame
 * end by the independent verifier: no NaN, bounded speed, zero intersecting
 * triangle pairs. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "import/import.h"
#include "sim/ccd.h"
#include "sim/internal.h"
#include "sim/selfcol.h"
#include "sim/vec3.h"

static double frand(unsigned *seed)
{
    *seed = *seed * 1103515245u + 12345u;
    return ((*seed >> 8) & 0xffff) / 65535.0;
}

/* ------------------------------------------------------------ cubic */

static void expect_root_near(const double *roots, int n, double want, double tol)
{
    for (int k = 0; k < n; k++)
        if (fabs(roots[k] - want) <= tol)
            return;
    fail_msg("root %.17g not found among %d", want, n);
}

static void test_cubic_constructed_roots(void **state)
{
    (void)state;
    unsigned seed = 1;
    double roots[8];
    for (int trial = 0; trial < 20000; trial++) {
        /* a (t - r1)(t - r2)(t - r3) with roots in [0, 1], scaled wildly */
        double r[3] = {frand(&seed), frand(&seed), frand(&seed)};
        if (trial % 7 == 0)
            r[1] = r[0];                      /* double root: a grazing touch */
        if (trial % 11 == 0)
            r[1] = r[2] = r[0];               /* triple root */
        if (trial % 13 == 0)
            r[0] = 0;                         /* exactly at the step's start */
        if (trial % 17 == 0)
            r[2] = 1;                         /* exactly at its end */
        double a = pow(10, -12 + 24 * frand(&seed)) * (frand(&seed) < 0.5 ? -1 : 1);
        double b = -a * (r[0] + r[1] + r[2]);
        double c = a * (r[0] * r[1] + r[1] * r[2] + r[0] * r[2]);
        double d = -a * r[0] * r[1] * r[2];
        int n = cs_cubic_roots_01(a, b, c, d, roots);
        for (int k = 0; k < n; k++)
            assert_true(roots[k] >= 0 && roots[k] <= 1);
        for (int k = 0; k < 3; k++) {
            /* a simple root is found to round-off; a multiple root only to
             * the square (cube) root of it, as conditioning dictates */
            int mult = (fabs(r[k] - r[(k + 1) % 3]) < 1e-12) + (fabs(r[k] - r[(k + 2) % 3]) < 1e-12);
            double tol = mult == 0 ? 1e-9 : mult == 1 ? 1e-6 : 1e-4;
            expect_root_near(roots, n, r[k], tol);
        }
    }
    /* quadratic, linear and constant degenerations */
    int n = cs_cubic_roots_01(0, 1, -0.75, 0.125, roots); /* (t - .25)(t - .5) */
    expect_root_near(roots, n, 0.25, 1e-12);
    expect_root_near(roots, n, 0.5, 1e-12);
    n = cs_cubic_roots_01(0, 0, 2, -1, roots);
    expect_root_near(roots, n, 0.5, 1e-15);
    n = cs_cubic_roots_01(0, 0, 0, 1, roots);
    assert_int_equal(n, 0);
    n = cs_cubic_roots_01(1, 0, 0, 1e-3, roots); /* only root at -0.1 */
    assert_int_equal(n, 0);
}

/* Four points whose motion makes them coplanar at a chosen time: the
 * candidate times must include it (to the accuracy of the motion). */
static void test_coplanarity_times_find_the_crossing(void **state)
{
    (void)state;
    unsigned seed = 7;
    for (int trial = 0; trial < 5000; trial++) {
        double a[3], b[3], c[3], p[3], va[3], vb[3], vc[3], vp[3], times[CS_CCD_MAX_TIMES];
        double tc = frand(&seed);
        if (trial % 5 == 0)
            tc = trial % 10 == 0 ? 0.0 : 1.0;
        for (int k = 0; k < 3; k++) {
            a[k] = frand(&seed), b[k] = frand(&seed), c[k] = frand(&seed);
            va[k] = frand(&seed) - 0.5, vb[k] = frand(&seed) - 0.5, vc[k] = frand(&seed) - 0.5;
        }
        /* p(t) = at time tc a point inside the triangle's plane, elsewhere
         * off it: p(tc) = barycentric combination of a, b, c at tc */
        double w[3] = {0.2, 0.3, 0.5}, q[3], off[3];
        for (int k = 0; k < 3; k++) {
            q[k] = w[0] * (a[k] + tc * va[k]) + w[1] * (b[k] + tc * vb[k]) +
                   w[2] * (c[k] + tc * vc[k]);
            vp[k] = frand(&seed) - 0.5;
            off[k] = 0;
        }
        (void)off;
        for (int k = 0; k < 3; k++)
            p[k] = q[k] - tc * vp[k];
        int n = cs_coplanarity_times(a, b, c, p, va, vb, vc, vp, times);
        double best = INFINITY;
        for (int i = 0; i < n; i++)
            best = fmin(best, fabs(times[i] - tc));
        assert_true(best < 1e-7);
    }
    /* motion within one plane: the cubic vanishes, times are sampled */
    double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 0, 1}, p[3] = {2, 0, 2};
    double v0[3] = {0, 0, 0}, vp[3] = {-3, 0, -3}, times[CS_CCD_MAX_TIMES];
    int n = cs_coplanarity_times(a, b, c, p, v0, v0, v0, vp, times);
    assert_true(n > 16);
}

/* ------------------------------------------------------ impact zones */

static void check_zone(int n, const double *x0, const double *m, unsigned seed)
{
    int idx[8];
    double u[24], x[24], vcm[3], w[3];
    for (int i = 0; i < n; i++) {
        idx[i] = i;
        for (int k = 0; k < 3; k++)
            u[3 * i + k] = frand(&seed) - 0.5;
    }
    double span = 0.01;
    cs_impact_zone_motion(n, idx, m, x0, u, span, x, vcm, w);
    /* linear momentum */
    double M = 0, P[3] = {0, 0, 0}, xcm[3] = {0, 0, 0};
    for (int i = 0; i < n; i++) {
        M += m[i];
        cs_axpy(m[i], u + 3 * i, P);
        cs_axpy(m[i], x0 + 3 * i, xcm);
    }
    for (int k = 0; k < 3; k++) {
        assert_true(fabs(M * vcm[k] - P[k]) < 1e-12);
        xcm[k] /= M;
    }
    /* angular momentum about the centre of mass: the rigid velocity field
     * v + w x r carries exactly the zone's L */
    double L[3] = {0, 0, 0}, Lr[3] = {0, 0, 0};
    for (int i = 0; i < n; i++) {
        double r[3], du[3], c1[3], wr[3], c2[3];
        cs_sub(x0 + 3 * i, xcm, r);
        cs_sub(u + 3 * i, vcm, du);
        cs_cross(r, du, c1);
        cs_axpy(m[i], c1, L);
        cs_cross(w, r, wr);
        cs_cross(r, wr, c2);
        cs_axpy(m[i], c2, Lr);
    }
    for (int k = 0; k < 3; k++)
        assert_true(fabs(L[k] - Lr[k]) < 1e-10);
    /* a rigid motion: distances kept */
    for (int i = 0; i < n; i++)
        for (int j = i + 1; j < n; j++) {
            double d0[3], d1[3];
            cs_sub(x0 + 3 * i, x0 + 3 * j, d0);
            cs_sub(x + 3 * i, x + 3 * j, d1);
            assert_true(fabs(cs_norm(d0) - cs_norm(d1)) < 1e-12);
        }
    for (int k = 0; k < 3 * n; k++)
        assert_true(isfinite(x[k]));
}

static void test_impact_zones_conserve_momentum(void **state)
{
    (void)state;
    double m[8] = {1, 2, 1.5, 0.5, 3, 1, 1, 2};
    double general[] = {0, 0, 0, 1, 0.2, 0, 0.3, 1, 0.1, 0.2, 0.4, 1, 0.5, 0.5, 0.5};
    double coplanar[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0.5, 0.3, 0};
    double colinear[] = {0, 0, 0, 1, 1, 1, 2, 2, 2, -1, -1, -1};
    double coincident[] = {0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3};
    check_zone(5, general, m, 3);
    check_zone(5, coplanar, m, 5);
    check_zone(4, colinear, m, 7);
    check_zone(3, coincident, m, 11);
}

/* ------------------------------------------------ scenes, every frame */

static void run_scene(const char *name, const char *text, int noverrides,
                      const char *const *overrides, double speed_bound)
{
    cs_scene *scene = NULL;
    char err[512];
    if (cs_scene_load_string(text, name, noverrides, overrides, &scene, err, sizeof err))
        fail_msg("%s", err);
    cs_sim *sim = cs_sim_create(&scene->def, err, sizeof err);
    if (!sim)
        fail_msg("%s: %s", name, err);
    long collisions = 0, zones = 0, repulsions = 0;
    for (int f = 1; f <= scene->frames; f++) {
        cs_frame_stats st;
        int rc = cs_sim_advance_frame(sim, &st);
        if (rc != CS_OK)
            fail_msg("%s: unstable at frame %d", name, f);
        const double *x = cs_sim_positions(sim), *v = cs_sim_velocities(sim);
        for (int k = 0; k < 3 * cs_sim_particle_count(sim); k++)
            if (!isfinite(x[k]) || !isfinite(v[k]))
                fail_msg("%s: NaN at frame %d", name, f);
        if (!(st.max_speed < speed_bound))
            fail_msg("%s: speed %.3g at frame %d", name, st.max_speed, f);
        long crossing = cs_sim_count_intersections(sim);
        if (crossing != 0)
            fail_msg("%s: %ld intersecting triangle pairs at the end of frame %d", name,
                     crossing, f);
        collisions += st.collisions;
        zones += st.impact_zones;
        repulsions += st.repulsions;
    }
    print_message("%s: %d frames clean; %ld repulsions, %ld collisions, %ld impact zones\n",
                  name, scene->frames, repulsions, collisions, zones);
    cs_sim_destroy(sim);
    cs_scene_destroy(scene);
}

/* A pinned triangle in y = 0 and a small free triangle. */
#define FLOOR_TRIANGLE                                                                       \
    "  - name: floor\n"                                                                      \
    "    mesh: {vertices: [[-1, 0, -1], [1, 0, -1], [0, 0, 1]], triangles: [[0, 1, 2]]}\n" \
    "    pins: [{vertices: [0, 1, 2]}]\n"

/* Eight frames without gravity: the floor, then a free "dart" triangle. */
#define DART_OVER_FLOOR                                                                      \
    "time: {fps: 50, frames: 8, dt: 2e-4}\n"                                                 \
    "gravity: [0, 0, 0]\n"                                                                   \
    "effects: {self_collision: true}\n"                                                      \
    "cloths:\n" FLOOR_TRIANGLE "  - name: dart\n"

static void test_point_on_triangle_moving_in_its_plane(void **state)
{
    (void)state;
    /* the dart's tip lies exactly in the floor's plane, outside it, and
     * slides within that plane into the triangle: the coplanarity cubic
     * vanishes identically all the way */
    const char *scene = DART_OVER_FLOOR
                        "    mesh: {vertices: [[0, 0, 1.05], [0.2, 0.1, 1.2], [-0.2, 0.1, 1.2]],\n"
                        "           triangles: [[0, 1, 2]]}\n"
                        "    velocity: [0, 0, -1]\n";
    run_scene("point moving in a triangle's plane", scene, 0, NULL, 10);
}

static void test_edge_through_an_endpoint(void **state)
{
    (void)state;
    /* the dart's edge (0)-(1) is vertical at z = 1 and sweeps along -x
     * exactly through the floor's vertex (0, 0, 1) at t = 0.08 s */
    const char *scene = DART_OVER_FLOOR
                        "    mesh: {vertices: [[0.024, -0.1, 1], [0.024, 0.1, 1], [0.124, 0.1, 1.2]],\n"
                        "           triangles: [[0, 1, 2]]}\n"
                        "    velocity: [-0.3, 0, 0]\n";
    run_scene("edge through an endpoint", scene, 0, NULL, 10);
}

static void test_parallel_and_colinear_edges(void **state)
{
    (void)state;
    /* coplanar triangles in y = 0 meeting edge-on along a common line, and
     * a parallel edge sliding above it */
    const char *scene = "time: {fps: 50, frames: 10, dt: 2e-4}\n"
                        "gravity: [0, 0, 0]\n"
                        "effects: {self_collision: true}\n"
                        "cloths:\n"
                        "  - name: left\n"
                        "    mesh: {vertices: [[-1, 0, 0], [0, 0, 0], [-0.5, 0, 0.5]],\n"
                        "           triangles: [[0, 1, 2]]}\n"
                        "    pins: [{vertices: [0, 2]}]\n"
                        "  - name: right\n"
                        "    mesh: {vertices: [[0.05, 0, 0], [1, 0, 0], [0.5, 0, 0.5]],\n"
                        "           triangles: [[0, 1, 2]]}\n"
                        "    velocity: [-1, 0, 0]\n"
                        "  - name: above\n"
                        "    mesh: {vertices: [[-0.6, 0.004, 0], [0.6, 0.004, 0], [0, 0.004, -0.4]],\n"
                        "           triangles: [[0, 1, 2]]}\n"
                        "    velocity: [0.2, -0.1, 0]\n";
    run_scene("parallel and colinear edges", scene, 0, NULL, 10);
}

static void test_zero_area_triangle(void **state)
{
    (void)state;
    /* a cloth with a degenerate (colinear) triangle falls onto a pinned one */
    const char *scene = "time: {fps: 50, frames: 10, dt: 2e-4}\n"
                        "gravity: [0, -9.8, 0]\n"
                        "effects: {self_collision: true}\n"
                        "cloths:\n" FLOOR_TRIANGLE
                        "  - name: sliver\n"
                        "    mesh: {vertices: [[-0.1, 0.03, 0], [0, 0.03, 0], [0.1, 0.03, 0],\n"
                        "                      [0, 0.03, 0.15]],\n"
                        "           triangles: [[0, 1, 2], [0, 2, 3]]}\n"
                        "    velocity: [0, -1, 0]\n";
    run_scene("zero-area triangle", scene, 0, NULL, 20);
}

static void test_contact_at_the_step_ends(void **state)
{
    (void)state;
    /* Without repulsions (a thickness far below the distances), the dart's
     * tip reaches the floor exactly at the end of the first step (t = 1),
     * and a second dart starts touching the floor, moving into it (t = 0);
     * step C alone must stop both. */
    const char *scene = "time: {fps: 100, frames: 5, dt: 1e-3, collision_steps: 1}\n"
                        "gravity: [0, 0, 0]\n"
                        "effects: {self_collision: true}\n"
                        "self_collision: {thickness: 1e-7}\n"
                        "cloths:\n" FLOOR_TRIANGLE
                        "  - name: end\n"
                        "    mesh: {vertices: [[0.1, 0.001, 0], [0.3, 0.2, 0], [0.3, 0.2, 0.1]],\n"
                        "           triangles: [[0, 1, 2]]}\n"
                        "    velocity: [0, -1, 0]\n"
                        "  - name: start\n"
                        "    mesh: {vertices: [[-0.3, 0, 0], [-0.5, 0.2, 0], [-0.5, 0.2, 0.1]],\n"
                        "           triangles: [[0, 1, 2]]}\n"
                        "    velocity: [0, -1, 0]\n";
    run_scene("contact at t = 1 and t = 0", scene, 0, NULL, 10);
}

static char *read_scene(const char *file)
{
    char path[512];
    snprintf(path, sizeof path, "%s/scenes/%s", CS_SOURCE_DIR, file);
    FILE *f = fopen(path, "rb");
    if (!f)
        fail_msg("cannot read %s", path);
    char *text = calloc(1, 1 << 16);
    size_t n = fread(text, 1, (1 << 16) - 1, f);
    text[n] = '\0';
    fclose(f);
    return text;
}

static void test_stack_of_sheets(void **state)
{
    (void)state;
    char *text = read_scene("stack.yaml");
    run_scene("stack of sheets", text, 0, NULL, 20);
    free(text);
}

/* Bridson et al. 2002's rewind-and-halve scheme (Fig. 14's comparison)
 * keeps the same invariant. */
static void test_rewind_scheme_stack(void **state)
{
    (void)state;
    char *text = read_scene("stack.yaml");
    const char *o[] = {"self_collision.scheme=rewind", "time.frames=12"};
    run_scene("stack of sheets, rewind scheme", text, 2, o, 20);
    free(text);
}

/* Positions and velocities of two runs of one scene, bit for bit. */
static bool same_state(const cs_sim *a, const cs_sim *b)
{
    size_t bytes = sizeof(double) * 3 * (size_t)cs_sim_particle_count(a);
    return memcmp(cs_sim_positions(a), cs_sim_positions(b), bytes) == 0 &&
           memcmp(cs_sim_velocities(a), cs_sim_velocities(b), bytes) == 0;
}

/* The broad phase only filters: the pairs of steps A and C, and so every
 * frame, are the same bits whether each search traverses the trees, reuses
 * the candidates kept since an earlier search (the default), or keeps them
 * with a far wider slack, and whether step A's distance skin and reach
 * test spare the makers the pairs they show to be far or every pair is
 * measured (the first sim, the reference). A pair the kept candidates
 * missed, or one the skin or the reach test dropped wrongly, would show as
 * a different frame. */
static void test_broad_phase_changes_nothing(void **state)
{
    (void)state;
    char *text = read_scene("stack.yaml");
    const char *o[] = {"time.frames=10"};
    cs_scene *scene = NULL;
    char err[512];
    if (cs_scene_load_string(text, "stack", 1, o, &scene, err, sizeof err))
        fail_msg("%s", err);
    const double slack[3] = {-1, 0.5, 8};
    cs_sim *sim[3];
    for (int k = 0; k < 3; k++) {
        sim[k] = cs_sim_create(&scene->def, err, sizeof err);
        assert_non_null(sim[k]);
        sim[k]->selfcol->cache.slack = slack[k];
    }
    sim[0]->selfcol->cache.skin_off = true;
    sim[0]->selfcol->cache.reach_off = true;
    long searches[3] = {0}, traversals[3] = {0}, collisions = 0, repulsions = 0;
    for (int f = 1; f <= scene->frames; f++) {
        long found[3];
        for (int k = 0; k < 3; k++) {
            cs_frame_stats st;
            assert_int_equal(cs_sim_advance_frame(sim[k], &st), CS_OK);
            found[k] = st.repulsion_pairs;
            searches[k] += st.pair_searches;
            traversals[k] += st.pair_traversals;
            if (k == 0) {
                collisions += st.collisions;
                repulsions += st.repulsions;
            }
        }
        for (int k = 1; k < 3; k++)
            if (!same_state(sim[0], sim[k]) || found[k] != found[0])
                fail_msg("frame %d differs with slack %g (%ld repulsion pairs against %ld)", f,
                         slack[k], found[k], found[0]);
    }
    /* the comparison means something: pairs were found, and the kept
     * candidates served most searches */
    assert_true(collisions > 0 && repulsions > 0);
    assert_int_equal(traversals[0], searches[0]);
    assert_true(traversals[1] < searches[1]);
    assert_true(traversals[2] <= traversals[1]);
    assert_true(sim[0]->selfcol->cache.skin_skips == 0 && sim[1]->selfcol->cache.skin_skips > 0);
    const cs_pair_cache *ref = &sim[0]->selfcol->cache, *kept = &sim[1]->selfcol->cache;
    assert_true(ref->reach_skips == 0 && ref->reach_traversals == 0);
    /* both of step A's ways past the cache ran: a traversal within reach
     * where the cache lasted one search (the default slack), the reach
     * test on cached candidates where a wide slack keeps the cache */
    const cs_pair_cache *wide = &sim[2]->selfcol->cache;
    assert_true(kept->reach_traversals > 0 && wide->reach_skips > 0);
    print_message("broad phase: %ld searches; traversals %ld, %ld, %ld (%ld within reach); %ld "
                  "collisions; the reach test skipped %ld candidates, the skin spared %ld pairs\n",
                  searches[0], traversals[0], traversals[1], traversals[2],
                  kept->reach_traversals, collisions, wide->reach_skips, kept->skin_skips);
    for (int k = 0; k < 3; k++)
        cs_sim_destroy(sim[k]);
    cs_scene_destroy(scene);
    free(text);
}

/* Step A's pairs of frame 1 (one outer step): a small free triangle 3 mm
 * over the pinned floor triangle, thickness 1 mm, moving at 1 m/s for a
 * 4 ms span, sideways or down, with self_collision.pruning set. */
static long first_step_pairs(const char *pruning, const char *velocity)
{
    char text[1024], option[64];
    snprintf(text, sizeof text,
             "time: {fps: 250, frames: 1, dt: 1e-3, collision_steps: 4}\n"
             "gravity: [0, 0, 0]\n"
             "effects: {self_collision: true}\n"
             "self_collision: {thickness: 0.001}\n"
             "cloths:\n" FLOOR_TRIANGLE
             "  - name: dart\n"
             "    mesh: {vertices: [[0, 0.003, 0], [0.1, 0.003, 0], [0, 0.003, 0.1]],\n"
             "           triangles: [[0, 1, 2]]}\n"
             "    velocity: %s\n",
             velocity);
    snprintf(option, sizeof option, "self_collision.pruning=%s", pruning);
    const char *o[] = {option};
    cs_scene *scene = NULL;
    char err[512];
    if (cs_scene_load_string(text, "pruning", 1, o, &scene, err, sizeof err))
        fail_msg("%s", err);
    cs_sim *sim = cs_sim_create(&scene->def, err, sizeof err);
    if (!sim)
        fail_msg("%s", err);
    cs_frame_stats st;
    assert_int_equal(cs_sim_advance_frame(sim, &st), CS_OK);
    assert_int_equal(cs_sim_count_intersections(sim), 0);
    cs_sim_destroy(sim);
    cs_scene_destroy(scene);
    return st.repulsion_pairs;
}

/* The two broad phases of step A. Moving sideways, the triangle's corners
 * stay 3 mm over the floor: `speed` keeps them as pairs (3 mm is within
 * the thickness plus 1 m/s times the span) and `path` does not (their
 * straight paths never come within the thickness). Moving down they reach
 * the floor within the span, and both keep the same pairs. */
static void test_path_pruning_keeps_only_approaching_pairs(void **state)
{
    (void)state;
    long speed_side = first_step_pairs("speed", "[1, 0, 0]");
    long path_side = first_step_pairs("path", "[1, 0, 0]");
    long speed_down = first_step_pairs("speed", "[0, -1, 0]");
    long path_down = first_step_pairs("path", "[0, -1, 0]");
    print_message("pairs: sideways %ld (speed) %ld (path), down %ld %ld\n", speed_side,
                  path_side, speed_down, path_down);
    assert_int_equal(speed_side, 3);
    assert_int_equal(path_side, 0);
    assert_int_equal(speed_down, 3);
    assert_int_equal(path_down, 3);
}

/* Path pruning on tangled cloth keeps the invariant too. */
static void test_path_pruning_stack(void **state)
{
    (void)state;
    char *text = read_scene("stack.yaml");
    const char *o[] = {"self_collision.pruning=path"};
    run_scene("stack of sheets, path pruning", text, 1, o, 20);
    free(text);
}

/* Step C skips its first search when step A's gap says no pair can come
 * within reach (start_gap): the stack's sheets, falling apart and then
 * landing on each other, must be the same bits at every frame with the
 * skip as without it, and the comparison must mean something: searches
 * skipped while the sheets fell, collisions found once they met. */
static void test_start_gap_skips_only_empty_searches(void **state)
{
    (void)state;
    char *text = read_scene("stack.yaml");
    /* the small fixed step: enough searches in the fall to skip */
    const char *o[] = {"time.frames=12", "time.step_limit=undamped"};
    cs_scene *scene = NULL;
    char err[512];
    if (cs_scene_load_string(text, "stack", 2, o, &scene, err, sizeof err))
        fail_msg("%s", err);
    cs_sim *sim[2];
    for (int k = 0; k < 2; k++) {
        sim[k] = cs_sim_create(&scene->def, err, sizeof err);
        assert_non_null(sim[k]);
        sim[k]->selfcol->use_start_gap = k == 0;
    }
    long collisions = 0;
    for (int f = 1; f <= scene->frames; f++) {
        for (int k = 0; k < 2; k++) {
            cs_frame_stats st;
            assert_int_equal(cs_sim_advance_frame(sim[k], &st), CS_OK);
            if (k == 0)
                collisions += st.collisions;
        }
        if (!same_state(sim[0], sim[1]))
            fail_msg("frame %d differs with step C's skip", f);
    }
    const cs_selfcol_stats *with = &sim[0]->selfcol->stats, *without = &sim[1]->selfcol->stats;
    assert_true(collisions > 0);
    assert_true(with->searches_skipped > 0);
    assert_int_equal(without->searches_skipped, 0);
    assert_int_equal(with->passes, without->passes);
    print_message("start gap: %ld of %ld step C passes needed no search; %ld collisions\n",
                  with->searches_skipped, with->passes, collisions);
    for (int k = 0; k < 2; k++)
        cs_sim_destroy(sim[k]);
    cs_scene_destroy(scene);
    free(text);
}

static void test_twist_strip_knots_cleanly(void **state)
{
    (void)state;
    /* Fig. 3 at test size: 5,000 triangles; heavier cloth and faster ends so
     * it is tightly wound within the test's budget */
    char *text = read_scene("twist.yaml");
    const char *o[] = {"time.frames=20", "cloths.0.material.density=8",
                       "cloths.0.scripts.0.motion.angular_velocity=[18.85, 0, 0]",
                       "cloths.0.scripts.1.motion.angular_velocity=[-18.85, 0, 0]"};
    run_scene("twisting strip", text, 4, o, 50);
    free(text);
}

static void test_ball_pushes_through_folds(void **state)
{
    (void)state;
    char *text = read_scene("curtain_ball.yaml");
    run_scene("ball through folds", text, 0, NULL, 50);
    free(text);
}

/* test_selfcol [--only PATTERN | --skip PATTERN]: the cases whose names
 * match cmocka's PATTERN (* and ? wildcards), or all but those. ctest runs
 * the two twisting strips and the rest as three entries side by side
 * (tests/CMakeLists.txt); in one they came close to its 300 s timeout
 * under ASan. */
int main(int argc, char **argv)
{
    if (argc == 3 && strcmp(argv[1], "--only") == 0) {
        cmocka_set_test_filter(argv[2]);
    } else if (argc == 3 && strcmp(argv[1], "--skip") == 0) {
        cmocka_set_skip_filter(argv[2]);
    } else if (argc != 1) {
        fprintf(stderr, "usage: %s [--only PATTERN | --skip PATTERN]\n", argv[0]);
        return 2;
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cubic_constructed_roots),
        cmocka_unit_test(test_coplanarity_times_find_the_crossing),
        cmocka_unit_test(test_impact_zones_conserve_momentum),
        cmocka_unit_test(test_point_on_triangle_moving_in_its_plane),
        cmocka_unit_test(test_edge_through_an_endpoint),
        cmocka_unit_test(test_parallel_and_colinear_edges),
        cmocka_unit_test(test_zero_area_triangle),
        cmocka_unit_test(test_contact_at_the_step_ends),
        cmocka_unit_test(test_stack_of_sheets),
        cmocka_unit_test(test_rewind_scheme_stack),
        cmocka_unit_test(test_broad_phase_changes_nothing),
        cmocka_unit_test(test_path_pruning_keeps_only_approaching_pairs),
        cmocka_unit_test(test_path_pruning_stack),
        cmocka_unit_test(test_start_gap_skips_only_empty_searches),
        cmocka_unit_test(test_twist_strip_knots_cleanly),
        cmocka_unit_test(test_ball_pushes_through_folds),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
