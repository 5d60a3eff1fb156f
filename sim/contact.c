/* contact.c: cloth-object collisions and friction (Section 6).
 *
 * Gamma(v) removes the part of v that moves into the body and applies
 * Coulomb friction in proportion to the normal velocity it removed.
 * The improved method finds where each particle crossed the level set,
 * applies Gamma to v^(n+1/2) to move on from there, keeps Gamma(v^n) for the
 * trapezoidal rule, and applies Gamma again to v_NP after the projected
 * solve (step B.7). The previous method (Bridson et al. 2003) projects the
 * position along the normal instead and applies Gamma after the solve to the
 * projected velocity, whose normal part is already gone.
 */
#include <limits.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "sim/body_grid.h"
#include "sim/internal.h"
#include "sim/vec3.h"

void cs_gamma(const double v[3], const double N[3], const double vb[3], double mu,
              double out[3])
{
    double vn = cs_dot(v, N), vbn = cs_dot(vb, N);
    double vt[3], vbt[3], vrel[3];
    for (int d = 0; d < 3; d++) {
        vt[d] = v[d] - vn * N[d];
        vbt[d] = vb[d] - vbn * N[d];
        vrel[d] = vt[d] - vbt[d];
    }
    double vn_star = vn > vbn ? vn : vbn;
    double speed = cs_norm(vrel);
    double scale = 0;
    if (speed > 0) {
        scale = 1.0 - mu * (vn_star - vn) / speed;
        if (scale < 0)
            scale = 0;
    }
    for (int d = 0; d < 3; d++)
        out[d] = vn_star * N[d] + vbt[d] + scale * vrel[d];
}

/* The body's Coulomb coefficient for the step from sim->t to sim->t + dt:
 * its value at the step's middle. Steady sliding gains dt (g sin theta -
 * mu g cos theta) in B.7 over the whole step, so for friction that changes
 * linearly within the step the midpoint is exact: on the incline of
 * tests/test_friction_schedule.c, where friction ramps down over 0.1 s, the
 * particle ends within 0.0025 of the test's tolerance of the analytic
 * distance, where the step's end (half a step late) puts it 1.3 mm off,
 * 4.6 times the tolerance. */
static double step_friction(const cs_sim *sim, const cs_body_def *body, double dt)
{
    return cs_body_def_friction(body, sim->t + 0.5 * dt);
}

/* The body as collisions see it: its surface moved out by the collision
 * offset (same gradient). */
static double contact_phi(const cs_body_def *body, const cs_body_pose *pose, const double x[3],
                          double g[3])
{
    return cs_body_posed_phi(body, pose, x, g) - body->offset;
}

/* Every body's pose at t1 = the step's end, once for the step's queries */
static void pose_bodies(cs_sim *sim, double t1)
{
    for (int b = 0; b < sim->nbodies; b++)
        cs_body_def_pose(sim->bodies + b, t1, sim->body_pose + b);
}

/* B.4 for particle i and body b; true when i is in contact with b (its
 * position then changed). Bodies are queried at time n+1, as the paper
 * prescribes. */
static bool collide_one(cs_sim *sim, int i, int b, double dt, bool improved)
{
    double *x = sim->x + 3 * i;
    const double *xn = sim->x_prev + 3 * i;
    double *vh = sim->v_half + 3 * i;
    const cs_body_def *body = sim->bodies + b;
    const cs_body_pose *pose = sim->body_pose + b;
    double N[3], vb[3], vstar[3];
    double phi1 = contact_phi(body, pose, x, N);
    if (!(phi1 < 0))
        return false;
    const double mu = step_friction(sim, body, dt);
    if (improved) {
        /* crossing point along the step; phi at time n of the point
         * x^n is phi_{n+1}(x^n) + dt v_BN (the body moved since) */
        double Nn[3];
        double phi0 = contact_phi(body, pose, xn, Nn);
        cs_body_posed_velocity(pose, xn, vb);
        phi0 += dt * cs_dot(vb, N);
        double theta = phi0 > 0 ? phi0 / (phi0 - phi1) : 0.0;
        if (theta > 1)
            theta = 1;
        double xc[3];
        for (int d = 0; d < 3; d++)
            xc[d] = xn[d] + theta * (x[d] - xn[d]);
        double Nc[3];
        cs_body_posed_phi(body, pose, xc, Nc);
        memcpy(N, Nc, sizeof N);
        cs_body_posed_velocity(pose, xc, vb);
        cs_gamma(vh, N, vb, mu, vstar);
        memcpy(vh, vstar, sizeof vstar);
        for (int d = 0; d < 3; d++)
            x[d] = xc[d] + (1.0 - theta) * dt * vstar[d];
        /* On curved or turning bodies the linearisation can leave the
         * point a little inside: finish along the normal there. */
        double g[3], phi = contact_phi(body, pose, x, g);
        if (phi < 0)
            cs_axpy(-phi, g, x);
    } else {
        cs_axpy(-phi1, N, x); /* Fig. 6 left: straight out along N */
        cs_body_posed_velocity(pose, x, vb);
    }
    cs_gamma(sim->v + 3 * i, N, vb, mu, sim->v_star + 3 * i);
    memcpy(sim->contact_normal + 3 * i, N, sizeof N);
    sim->contact_body[i] = b;
    return true;
}

/* The first body after `after` that a particle at x must meet: an
 * unbounded one, or a bounded one whose box holds x (a body whose box does
 * not hold a point has phi >= 0 there: meeting it would change nothing).
 * unbounded lists the unbounded bodies ascending; [first, last) of the
 * grid's cell_bodies are those of x's cell. nb when there is none. */
static int next_body(const cs_body_grid *g, const int *unbounded, int nunbounded, int nb,
                     const double x[3], int first, int last, int after)
{
    int next = nb;
    for (int k = 0; k < nunbounded; k++)
        if (unbounded[k] > after) {
            next = unbounded[k];
            break;
        }
    for (int j = first; j < last; j++) { /* ascending within a cell */
        int b = g->cell_bodies[j];
        if (b > after && b < next && cs_body_grid_inside(g, b, x)) {
            next = b;
            break;
        }
    }
    return next;
}

/* Step B.4: sim->x holds x~^(n+1) on entry and x^(n+1) on return; x_prev
 * is x^n, v_half is v~^(n+1/2). Sets v_star = Gamma(v^n) for particles in
 * contact (v^n elsewhere) and marks them CS_CONTACT with their normal;
 * checks v_star for a runaway.
 *
 * Each free point meets its bodies in ascending order, each seeing the
 * position the previous ones left: the unbounded bodies (planes) and the
 * bounded ones whose box holds it, found through the body grid's cells at
 * its present position (so a point one body pushes into another's box
 * meets that one too). A meeting changes only its own point, so the
 * threads share the points. This was a pass per body over lists of the
 * points in its box, built each step by two serial passes over every point
 * with the other threads waiting. */
void cs_body_collide(cs_sim *sim, double dt)
{
    int nb = sim->nbodies;
    bool improved = sim->def.friction_method == CS_FRICTION_IMPROVED;
    cs_body_grid g;
    cs_body_grid_build(&g, sim->bodies, nb, sim->t + dt, NULL, NULL, 0);
    pose_bodies(sim, sim->t + dt);
    int nunbounded = 0, *unbounded = malloc(((size_t)nb + 1) * sizeof *unbounded);
    for (int b = 0; unbounded && b < nb; b++)
        if (!g.ok || !g.bounded[b]) /* no grid (no memory): every body is asked */
            unbounded[nunbounded++] = b;
    long contacts = 0;
    double worst = 0; /* the runaway check of v_star, in the same pass */
    int nan_seen = 0;
    CS_PARALLEL_FOR_OWNED_WITH(sim->par, i, reduction(+ : contacts) reduction(max : worst)
                                                 reduction(|| : nan_seen)) {
        memcpy(sim->v_star + 3 * i, sim->v + 3 * i, 3 * sizeof(double));
        sim->contact_body[i] = -1;
        if (sim->active[i]) {
            const double *x = sim->x + 3 * i;
            int first, last;
            cs_body_grid_cell_bodies(&g, x, &first, &last);
            for (int b = -1; unbounded;) {
                b = next_body(&g, unbounded, nunbounded, nb, x, first, last, b);
                if (b >= nb)
                    break;
                if (collide_one(sim, i, b, dt, improved)) /* moved: maybe to another cell */
                    cs_body_grid_cell_bodies(&g, x, &first, &last);
            }
            if (!unbounded) /* no memory for the list: every body, in order */
                for (int b = 0; b < nb; b++)
                    collide_one(sim, i, b, dt, improved);
            if (sim->contact_body[i] >= 0) {
                sim->mode[i] = CS_CONTACT;
                contacts++;
            }
        }
        if (sim->is_free[i])
            cs_speed_seen(sim->v_star + 3 * i, &worst, &nan_seen);
    }
    cs_runaway_note(sim, CS_STAGE_BODY_COLLISION, worst, nan_seen);
    sim->contacts += contacts;
    free(unbounded);
    cs_body_grid_free(&g);
}

/* Step B.7: v_next holds v~^(n+1) (from v_NP for the improved method);
 * apply Gamma with the contact normal and the body's velocity at n+1, and
 * check the velocities it changes for a runaway (the others were checked
 * after B.6, which leaves these to B.7). */
void cs_body_friction(cs_sim *sim, double dt)
{
    double worst = 0;
    int nan_seen = 0;
    CS_PARALLEL_FOR_OWNED_WITH(sim->par, i, reduction(max : worst) reduction(|| : nan_seen)) {
        int b = sim->contact_body[i]; /* the poses of B.4, the same step's end */
        if (b < 0)
            continue;
        double vb[3], out[3];
        cs_body_posed_velocity(sim->body_pose + b, sim->x + 3 * i, vb);
        cs_gamma(sim->v_next + 3 * i, sim->contact_normal + 3 * i, vb,
                 step_friction(sim, sim->bodies + b, dt), out);
        memcpy(sim->v_next + 3 * i, out, sizeof out);
        if (sim->is_free[i])
            cs_speed_seen(out, &worst, &nan_seen);
    }
    cs_runaway_note(sim, CS_STAGE_BODY_FRICTION, worst, nan_seen);
}

/* The deepest point of the cloth's surface inside a body (its true
 * surface, not the collision offset): free vertices, and on every triangle
 * with a free vertex its centroid and edge midpoints. Vertices alone miss
 * what matters in pictures: a coarse cloth resting on a curved or detailed
 * body holds every vertex outside while the body pokes through between
 * them (18 mm on the duck, where the vertices said 0.1 mm). */
double cs_sim_body_penetration(const cs_sim *sim)
{
    if (!cs_plan_has(&sim->plan, CS_STAGE_BODY_COLLISION))
        return 0;
    size_t nt = 0;
    for (int c = 0; c < sim->ncloths; c++)
        nt += (size_t)sim->cloths[c].mesh->nt;
    size_t np = (size_t)sim->n + 4 * nt;
    if (np > INT_MAX)
        np = (size_t)sim->n; /* vertices only */
    double *p = malloc(3 * sizeof *p * np);
    unsigned char *use = malloc(np);
    if (!p || !use) {
        free(p);
        free(use);
        return -1;
    }
    memcpy(p, sim->x, 3 * sizeof *p * (size_t)sim->n);
    memcpy(use, sim->is_free, (size_t)sim->n);
    size_t k = (size_t)sim->n;
    for (int c = 0; c < sim->ncloths && np > (size_t)sim->n; c++) {
        const cs_trimesh *m = sim->cloths[c].mesh;
        for (int t = 0; t < m->nt; t++) {
            int v[3];
            for (int e = 0; e < 3; e++)
                v[e] = sim->cloths[c].offset + m->tri[3 * t + e];
            bool free_tri = sim->is_free[v[0]] || sim->is_free[v[1]] || sim->is_free[v[2]];
            for (int d = 0; d < 3; d++) {
                const double a = sim->x[3 * v[0] + d], b = sim->x[3 * v[1] + d],
                             cc = sim->x[3 * v[2] + d];
                p[3 * k + d] = (a + b + cc) / 3;
                p[3 * (k + 1) + d] = 0.5 * (a + b);
                p[3 * (k + 2) + d] = 0.5 * (b + cc);
                p[3 * (k + 3) + d] = 0.5 * (cc + a);
            }
            memset(use + k, free_tri, 4);
            k += 4;
        }
    }
    cs_body_grid g;
    cs_body_grid_build(&g, sim->bodies, sim->nbodies, sim->t, p, use, (int)k);
    double deepest = 0;
    for (int b = 0; b < sim->nbodies; b++) {
        bool listed = g.ok && g.bounded[b];
        size_t count = listed ? (size_t)(g.start[b + 1] - g.start[b]) : k;
        for (size_t j = 0; j < count; j++) {
            size_t i = listed ? (size_t)g.points[g.start[b] + j] : j;
            if (!use[i])
                continue;
            double grad[3], phi = cs_body_def_phi(sim->bodies + b, sim->t, p + 3 * i, grad);
            if (-phi > deepest)
                deepest = -phi;
        }
    }
    cs_body_grid_free(&g);
    free(p);
    free(use);
    return deepest;
}
