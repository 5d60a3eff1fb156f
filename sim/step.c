/* step.c: the time step of Section 3: its stages' work (the stage table
 * in stages.c runs them, and makes the step around them). */
#include <omp.h>
#include <string.h>

#include "sim/stages.h"
#include "sim/vec3.h"

/* force = elastic(x) + m g + explicit wind part at time t, and the solve's
 * right-hand side rhs = M v_start + (dt / 2) force, for owned particles
 * (the ghosts' forces are zero); one threaded pass after the springs' */
static void explicit_forces(cs_sim *sim, const double *x, const double *v_start, double t)
{
    if (cs_par_distributed(sim->par)) /* the ghosts' stay zero */
        CS_PARALLEL_FOR_LOCAL(sim->par, i)
            sim->force[3 * i] = sim->force[3 * i + 1] = sim->force[3 * i + 2] = 0;
    cs_springs_elastic(&sim->springs, x, sim->force); /* the owned rows' */
    double c = sim->def.wind.drag;
    CS_PARALLEL_FOR_OWNED(sim->par, i) {
        double *f = sim->force + 3 * i;
        cs_axpy(sim->mass[i], sim->def.gravity, f);
        if (sim->wind_normal) {
            const double *nrm = sim->wind_normal + 3 * i;
            double wind[3];
            cs_wind_at(&sim->def.wind, x + 3 * i, t, wind);
            cs_axpy(c * sim->wind_area[i] * cs_dot(nrm, wind), nrm, f);
        }
        for (int d = 0; d < 3; d++)
            sim->rhs[3 * i + d] = sim->mass[i] * v_start[3 * i + d] + sim->half_dt * f[d];
    }
}

/* Copies 3 doubles per particle over the given ranges, shared among the
 * threads (a serial copy left the other threads waiting, the copy all on
 * the main thread). */
static void copy_ranges(const int *ranges, int nranges, double *dst, const double *src)
{
    CS_PARALLEL_FOR_RANGES(ranges, nranges, i)
        memcpy(dst + 3 * i, src + 3 * i, 3 * sizeof(double));
}

/* The improved method applies B.5's forces without the contact
 * projection, so that B.7 sees the normal force. Where that force pulls a
 * contact particle off the body, nothing in B.5 damped the pull (the
 * projection held the normal velocity), and at steps far above the
 * undamped limit the explicit pull grows without bound. Such a particle
 * leaves the body: it takes the projected solve's velocity, as the
 * previous method would give it, and B.4 stops holding it next step. */
static void release_separating(cs_sim *sim, int i, const double *v_p)
{
    int b = sim->contact_body[i];
    if (b < 0)
        return;
    double vb[3], rel[3];
    cs_body_posed_velocity(sim->body_pose + b, sim->x + 3 * i, vb); /* B.4's, at t1 */
    cs_sub(sim->v_next + 3 * i, vb, rel);
    if (cs_dot(rel, sim->contact_normal + 3 * i) <= 0)
        return;
    for (int d = 0; d < 3; d++)
        sim->v_next[3 * i + d] = 2.0 * v_p[3 * i + d] - sim->v_star[3 * i + d];
}

/* Scripted (and pinned) particles end the step at their script's velocity */
static void hold_scripted(cs_sim *sim)
{
    CS_FOR_OWNED(sim->par, i)
        if (!sim->is_free[i])
            memcpy(sim->v_next + 3 * i, sim->script_v + 3 * i, 3 * sizeof(double));
}

/* ------------------------------------------------------------ the step
 *
 * The rows of one time step (Section 3's B.1-B.8, with the scripted
 * vertices and wind before them); the stage table (stages.c) orders them
 * and runs those the plan has. */

const double *cs_stage_scripted_vertices(cs_sim *sim, cs_stage_ctx *st)
{
    cs_script_targets(sim, st->t1, st->dt);
    return NULL;
}

const double *cs_stage_wind(cs_sim *sim, cs_stage_ctx *st)
{
    (void)st;
    cs_wind_geometry(sim, sim->x);
    return NULL;
}

/* Whether any owned particle is pinned or scripted (a serial scan of
 * bytes costs less than a threaded copy of velocities) */
static bool any_held(const cs_sim *sim)
{
    CS_FOR_OWNED(sim->par, i)
        if (!sim->is_free[i])
            return true;
    return false;
}

/* B.1: v~^(n+1/2) = v^n + dt/2 a(x^n, v~^(n+1/2)), unconstrained by
 * contact (constraining it would make cloth stick to bodies). Scripted
 * particles move straight to their targets. */
const double *cs_stage_velocity_half(cs_sim *sim, cs_stage_ctx *st)
{
    cs_par *par = sim->par;
    const double *v0 = sim->v; /* the start: v^n, where nothing is held */
    if (any_held(sim)) {
        copy_ranges(par->own, par->nown, sim->v0, sim->v);
        CS_FOR_OWNED(par, i)
            if (!sim->is_free[i])
                for (int d = 0; d < 3; d++)
                    sim->v0[3 * i + d] = (sim->script_x[3 * i + d] - sim->x[3 * i + d]) / st->dt;
        v0 = sim->v0;
    }
    explicit_forces(sim, sim->x, sim->v, sim->t); /* prepares the springs' directions at x^n too */
    sim->cg_iterations += cs_cg_solve(sim, v0, sim->rhs, sim->v_half, NULL, sim->cg.warm_half,
                                      sim->cg.warm_half_before, CS_STAGE_VELOCITY_HALF);
    return NULL; /* checked */
}

/* What B.2 or B.8 leaves to check: v, unless no pair was near on this
 * rank (then no velocity changed; with ranks, another's impulses may
 * arrive through the halo) */
static const double *repulsed(const cs_sim *sim, long near, const double *v)
{
    return near > 0 || sim->par->size > 1 ? v : NULL;
}

/* B.2: repulsions change only the velocity that moves the positions */
const double *cs_stage_self_repulsion(cs_sim *sim, cs_stage_ctx *st)
{
    return repulsed(sim, cs_selfcol_repulse(sim, sim->x, sim->v_half, st->dt, true), sim->v_half);
}

/* B.3; without bodies, v*^n is v^n */
const double *cs_stage_position_update(cs_sim *sim, cs_stage_ctx *st)
{
    CS_PARALLEL_FOR_OWNED(sim->par, i) {
        if (sim->is_free[i]) {
            for (int d = 0; d < 3; d++)
                sim->x[3 * i + d] = sim->x_prev[3 * i + d] + st->dt * sim->v_half[3 * i + d];
        } else { /* exact targets, free of round-off */
            memcpy(sim->x + 3 * i, sim->script_x + 3 * i, 3 * sizeof(double));
        }
    }
    if (!st->bodies)
        copy_ranges(sim->par->own, sim->par->nown, sim->v_star, sim->v);
    return NULL;
}

/* B.4 */
const double *cs_stage_body_collision(cs_sim *sim, cs_stage_ctx *st)
{
    cs_body_collide(sim, st->dt);
    return NULL; /* checked */
}

/* B.5 and B.6: v^(n+1/2) = v*^n + dt/2 a(x^(n+1/2), v^(n+1/2)) with the
 * normal velocity of contact particles held (P), then
 * v^(n+1) = 2 v^(n+1/2) - v*^n. The improved method extrapolates from
 * v_NP: the same forces, damping evaluated at the projected solution,
 * applied without projection, so B.7 sees the normal force. The ghosts'
 * new positions (B.3's and B.4's) arrive first. */
const double *cs_stage_velocity_full(cs_sim *sim, cs_stage_ctx *st)
{
    cs_par *par = sim->par;
    cs_halo_forward(par, &par->ghosts, sim->x, 3);
    CS_FOR_OWNED(par, i)
        if (!sim->is_free[i])
            memcpy(sim->v_star + 3 * i, sim->v0 + 3 * i, 3 * sizeof(double));
    CS_PARALLEL_FOR_LOCAL(par, i) /* x^(n+1/2), reusing v_half */
        for (int d = 0; d < 3; d++)
            sim->v_half[3 * i + d] = 0.5 * (sim->x_prev[3 * i + d] + sim->x[3 * i + d]);
    explicit_forces(sim, sim->v_half, sim->v_star, st->t1 - 0.5 * st->dt); /* at x^(n+1/2) */
    double *v_p = sim->v0; /* v0 is free again */
    /* B.5's response is predicted as this step's B.1 response (the same
     * springs, half a step later) plus how B.5's exceeded B.1's lately */
    sim->cg_iterations += cs_cg_solve(sim, sim->v_star, sim->rhs, v_p, sim->cg.warm_half,
                                      sim->cg.warm_full_less_half,
                                      sim->cg.warm_full_less_half_before, -1);
    if (!(st->bodies && sim->def.friction_method == CS_FRICTION_IMPROVED)) {
        CS_PARALLEL_FOR_OWNED(par, i)
            for (int d = 0; d < 3; d++)
                sim->v_next[3 * i + d] = 2.0 * v_p[3 * i + d] - sim->v_star[3 * i + d];
        hold_scripted(sim);
        return sim->v_next;
    }
    /* One pass over the rows: F_i + F_d v_P, B.6 from it, and the runaway
     * check (a copy of the forces, the damping pass, B.6 and the check
     * were four passes, each with a fork; the same bits). The rows are
     * shared among the threads as CG's are (shares.h). */
    cs_halo_forward(par, &par->ghosts, v_p, 3);
    const int *own = cs_par_owned(par);
    double worst = 0;
    int nan_seen = 0;
#pragma omp parallel reduction(max : worst) reduction(|| : nan_seen)
    {
        double t0 = omp_get_wtime();
        int r0, r1;
        cs_shares_rows(&sim->shares, par->nowned, &r0, &r1);
        for (int r = r0; r < r1; r++) {
            int i = own[r];
            double f[3];
            memcpy(f, sim->force + 3 * i, sizeof f);
            cs_damping_row(sim, r, i, v_p, f);
            for (int d = 0; d < 3; d++) {
                int k = 3 * i + d;
                double v_np = sim->v_star[k] + sim->half_dt / sim->mass[i] * f[d];
                sim->v_next[k] = 2.0 * v_np - sim->v_star[k];
            }
            release_separating(sim, i, v_p);
            /* B.6's velocity in contact is not a speed yet: B.7's check */
            if (sim->is_free[i] && sim->mode[i] != CS_CONTACT)
                cs_speed_seen(sim->v_next + 3 * i, &worst, &nan_seen);
        }
        cs_shares_clock(&sim->shares, t0);
    }
    cs_runaway_note(sim, CS_STAGE_VELOCITY_FULL, worst, nan_seen);
    hold_scripted(sim);
    return NULL; /* checked */
}

/* B.7 */
const double *cs_stage_body_friction(cs_sim *sim, cs_stage_ctx *st)
{
    cs_body_friction(sim, st->dt);
    return NULL; /* checked */
}

/* B.8: inelastic repulsion and friction on the final velocity */
const double *cs_stage_self_friction(cs_sim *sim, cs_stage_ctx *st)
{
    return repulsed(sim, cs_selfcol_repulse(sim, sim->x, sim->v_next, st->dt, false), sim->v_next);
}
