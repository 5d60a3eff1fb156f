/* incline_analytic.h: runs an incline validation scene (scenes/validation)
 * at a chosen angle, friction and initial speed, through the same --set
 * overrides a user types, and measures it against the analytic solution.
 * Used by tests/test_incline.c.
 *
 * Analytic: cs_incline_motion (common/incline.h, the one definition, which
 * `clothsim sweep --analytic incline` uses too): a = (sin theta - mu cos
 * theta) g along the slope, x(t) = v0 t + a t^2 / 2 and v(t) = v0 + a t
 * until v reaches 0 (when mu > tan theta), then at rest. */
#ifndef CS_INCLINE_ANALYTIC_H
#define CS_INCLINE_ANALYTIC_H

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "common/incline.h"
#include "import/import.h"

#define G 9.8

typedef struct incline_result {
    double worst_position;  /* max over frames of error / tolerance */
    double max_error;       /* max over frames of |x - x_exact|, m */
    double worst_velocity;
    double displacement;    /* along the slope at the end */
    double exact;
    double stop_time;       /* first frame time the body no longer advanced, or -1 */
    double seconds;         /* wall time of the simulation */
    long cg_iterations;
} incline_result;

/* extra: further overrides (e.g. "time.dt=1e-3"), may be NULL. Returns 0,
 * or -1 with err filled. */
static int run_incline(const char *scene_file, double theta_deg, double mu, double v0,
                       const char *method, int nextra, const char *const *extra,
                       incline_result *out, char *err, size_t errlen)
{
    char path[512], o[5][128];
    snprintf(path, sizeof path, "%s/scenes/validation/%s", CS_SOURCE_DIR, scene_file);
    double th = theta_deg * M_PI / 180.0;
    double down[3] = {-cos(th), -sin(th), 0};
    snprintf(o[0], sizeof o[0], "bodies.0.rotation=[0, 0, %.17g]", theta_deg);
    snprintf(o[1], sizeof o[1], "cloths.0.mesh.rotation=[0, 0, %.17g]", theta_deg);
    snprintf(o[2], sizeof o[2], "bodies.0.friction=%.17g", mu);
    snprintf(o[3], sizeof o[3], "cloths.0.velocity=[%.17g, %.17g, 0]", v0 * down[0], v0 * down[1]);
    snprintf(o[4], sizeof o[4], "effects.friction=%s", method);
    const char *overrides[16] = {o[0], o[1], o[2], o[3], o[4]};
    for (int k = 0; k < nextra && k < 11; k++)
        overrides[5 + k] = extra[k];
    cs_scene *scene = NULL;
    if (cs_scene_load(path, 5 + (nextra < 11 ? nextra : 11), overrides, &scene, err, errlen))
        return -1;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    cs_sim *sim = cs_sim_create(&scene->def, err, errlen);
    if (!sim) {
        cs_scene_destroy(scene);
        return -1;
    }

    int n = cs_sim_particle_count(sim);
    const double *mass = cs_sim_masses(sim);
    double total = 0, com0[3] = {0, 0, 0};
    for (int i = 0; i < n; i++) {
        total += mass[i];
        for (int d = 0; d < 3; d++)
            com0[d] += mass[i] * cs_sim_positions(sim)[3 * i + d];
    }
    for (int d = 0; d < 3; d++)
        com0[d] /= total;

    cs_incline motion = cs_incline_make(G, theta_deg, mu, v0);
    incline_result res = {.stop_time = -1};
    double s_prev = 0, t_prev = 0;
    for (int f = 1; f <= scene->frames; f++) {
        cs_frame_stats stats;
        if (cs_sim_advance_frame(sim, &stats) != CS_OK) {
            snprintf(err, errlen, "%s: unstable at frame %d", scene_file, f);
            cs_sim_destroy(sim);
            cs_scene_destroy(scene);
            return -1;
        }
        res.cg_iterations += stats.cg_iterations;
        double t = cs_sim_time(sim), s = 0, vs = 0;
        for (int i = 0; i < n; i++)
            for (int d = 0; d < 3; d++) {
                s += mass[i] * (cs_sim_positions(sim)[3 * i + d] - com0[d]) * down[d] / total;
                vs += mass[i] * cs_sim_velocities(sim)[3 * i + d] * down[d] / total;
            }
        double exact, v_exact;
        cs_incline_motion(&motion, t, &exact, &v_exact);
        /* 1e-3 of the distance travelled, or 1e-4 m where that is smaller */
        double tol_x = fmax(1e-3 * fabs(exact), 1e-4);
        double tol_v = fmax(1e-3 * fabs(v_exact), 1e-3);
        res.worst_position = fmax(res.worst_position, fabs(s - exact) / tol_x);
        res.max_error = fmax(res.max_error, fabs(s - exact));
        res.worst_velocity = fmax(res.worst_velocity, fabs(vs - v_exact) / tol_v);
        res.displacement = s;
        res.exact = exact;
        /* Stopped when the centre of mass advances less than a tenth of the
         * position tolerance in a frame (an elastic tetrahedron tips forward
         * as friction stops its base and settles back). (The stored
         * velocity of a resting free particle keeps an O(dt g) remainder:
         * B.1 is unconstrained, as the paper requires, so the contact
         * particles' half-step velocity points into the plane and drags it
         * through the damping; positions do not move. The velocity check
         * above bounds it.) */
        if (res.stop_time < 0 && fabs(s - s_prev) < 1e-5)
            res.stop_time = t_prev; /* it stopped within the previous frame */
        s_prev = s;
        t_prev = t;
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    res.seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    cs_sim_destroy(sim);
    cs_scene_destroy(scene);
    *out = res;
    return 0;
}

#endif
