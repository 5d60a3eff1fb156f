/* step.c: the time step of Section 3 as a table of stages, the outer
 * collision loop of Section 4 around it, and a frame of outer steps. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/util.h"
#include "sim/internal.h"
#include "sim/vec3.h"

/* Each stage's time and calls, in one place. */
#define STAGE_BEGIN(sim, stage)                                        \
    double stage_t0_##stage = cs_now();                                \
    cs_par_begin((sim)->par, stage)
#define STAGE_END(sim, stage)                                          \
    do {                                                               \
        (sim)->timing[stage].seconds += cs_now() - stage_t0_##stage;   \
        (sim)->timing[stage].calls++;                                  \
    } while (0)

/* Targets of scripted vertices at the end t1 of a step of dt: position and
 * velocity, at the script's own time t1 - lag (lag 0 but after a hold). */
static void script_targets(cs_sim *sim, double t1, double dt)
{
    for (int s = 0; s < sim->nscripts; s++) {
        cs_script_state *sc = sim->scripts + s;
        if (sc->released)
            continue;
        double lag0 = sim->script_lag[s];
        double lag1 = fmax(0.0, lag0 - (CS_SCRIPT_CATCH_UP_RATE - 1.0) * dt);
        sim->script_lag[s] = lag1;
        double t = t1 - lag1, rate = 1.0 + (lag0 - lag1) / dt; /* script s per s */
        double R[9], c[3], vel[3], w[3];
        cs_motion_pose(&sc->motion, t, R, c, vel, w);
        for (int d = 0; d < 3; d++) {
            vel[d] *= rate;
            w[d] *= rate;
        }
        for (int j = 0; j < sc->nvertices; j++) {
            int g = sc->vertices[j];
            double r[3], wr[3];
            cs_mat_apply(R, sc->local + 3 * j, r);
            cs_cross(w, r, wr);
            for (int d = 0; d < 3; d++) {
                sim->script_x[3 * g + d] = c[d] + r[d];
                sim->script_v[3 * g + d] = vel[d] + wr[d];
            }
        }
    }
}

/* Scripts whose release time has come let their vertices go, at the start
 * of a step (a function of the time alone: every rank and a resumed run
 * release at the same step). The vertices keep the velocity the script
 * gave them at the end of the last step. */
static void release_scripts(cs_sim *sim, double dt)
{
    for (int s = 0; s < sim->nscripts; s++) {
        cs_script_state *sc = sim->scripts + s;
        if (sc->released || !(sc->release_time > 0) || sim->t < sc->release_time - 1e-9 * dt)
            continue;
        sc->released = true;
        for (int j = 0; j < sc->nvertices; j++) {
            int g = sc->vertices[j];
            sim->is_free[g] = 1;
            sim->active[g] = cs_par_owns(sim->par, g);
            if (sim->selfcol)
                cs_selfcol_release(sim->selfcol, g, sim->mass[g]);
        }
    }
}

void cs_scripts_hold_releasable(cs_sim *sim, bool hold)
{
    for (int s = 0; s < sim->nscripts; s++)
        if (sim->scripts[s].release_time > 0 && !sim->scripts[s].released)
            for (int j = 0; j < sim->scripts[s].nvertices; j++)
                sim->is_free[sim->scripts[s].vertices[j]] = !hold;
}

/* Area-weighted vertex normals and a third of the adjacent area. */
static void wind_geometry(cs_sim *sim, const double *x)
{
    memset(sim->wind_normal, 0, sizeof(double) * 3 * (size_t)sim->n);
    memset(sim->wind_area, 0, sizeof(double) * (size_t)sim->n);
    for (int c = 0; c < sim->ncloths; c++) {
        const cs_trimesh *m = sim->cloths[c].mesh;
        int off = sim->cloths[c].offset;
        for (int t = 0; t < m->nt; t++) {
            int a = off + m->tri[3 * t], b = off + m->tri[3 * t + 1], cc = off + m->tri[3 * t + 2];
            double e1[3], e2[3], cr[3];
            cs_sub(x + 3 * b, x + 3 * a, e1);
            cs_sub(x + 3 * cc, x + 3 * a, e2);
            cs_cross(e1, e2, cr); /* |cr| = twice the area */
            int v[3] = {a, b, cc};
            for (int k = 0; k < 3; k++) {
                cs_axpy(1.0, cr, sim->wind_normal + 3 * v[k]);
                sim->wind_area[v[k]] += cs_norm(cr) / 6.0;
            }
        }
    }
    for (int i = 0; i < sim->n; i++) {
        double *nrm = sim->wind_normal + 3 * i, l = cs_norm(nrm);
        if (l > 0)
            for (int d = 0; d < 3; d++)
                nrm[d] /= l;
    }
}

/* The ABC flow's phases advance at these multiples of 2 pi / gust_period:
 * ratios far from simple fractions, so the pattern never repeats exactly. */
static const double GUST_RATE[3] = {1.0, 0.6180339887498949, 0.4142135623730951};

void cs_wind_at(const cs_wind_def *w, const double p[3], double t, double out[3])
{
    double f = 1 - p[1] / w->ground_height;
    f = f < 0 ? 0 : f > 1 ? 1 : f;
    for (int d = 0; d < 3; d++)
        out[d] = w->velocity[d] + f * w->ground_boost[d];
    if (!(w->gust > 0))
        return;
    /* u = A (sin(kz + a_z) + cos(ky + a_y), sin(kx + a_x) + cos(kz + a_z),
     *        sin(ky + a_y) + cos(kx + a_x)): each component depends only on
     * the other two coordinates, so div u = 0; each is the sum of two
     * unit-amplitude waves, so its RMS over space is A. */
    double k = 2 * M_PI / w->gust_length, s = 2 * M_PI * t / w->gust_period, arg[3];
    for (int d = 0; d < 3; d++)
        arg[d] = k * p[d] + GUST_RATE[d] * s;
    out[0] += w->gust * (sin(arg[2]) + cos(arg[1]));
    out[1] += w->gust * (sin(arg[0]) + cos(arg[2]));
    out[2] += w->gust * (sin(arg[1]) + cos(arg[0]));
}

double cs_wind_max_speed(const cs_wind_def *w)
{
    /* each gust component is at most 2 A */
    return cs_norm(w->velocity) + cs_norm(w->ground_boost) + 2 * sqrt(3.0) * w->gust;
}

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
 * The stages of one time step (Section 3's B.1-B.8, with the scripted
 * vertices and wind before them), in order. The plan (plan.c) says which
 * the scene needs; cs_sim_step runs those, times each in one place and
 * checks the velocity each one makes for a runaway. Adding a stage is a
 * row here and one in plan.c. */
typedef struct step_state {
    double dt, t1;
    bool bodies; /* the plan has B.4 and B.7 */
} step_state;

typedef const double *(*stage_fn)(cs_sim *sim, const step_state *st);

static const double *stage_scripted_vertices(cs_sim *sim, const step_state *st)
{
    script_targets(sim, st->t1, st->dt);
    return NULL;
}

static const double *stage_wind(cs_sim *sim, const step_state *st)
{
    (void)st;
    wind_geometry(sim, sim->x);
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
static const double *stage_velocity_half(cs_sim *sim, const step_state *st)
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
static const double *stage_self_repulsion(cs_sim *sim, const step_state *st)
{
    return repulsed(sim, cs_selfcol_repulse(sim, sim->x, sim->v_half, st->dt, true), sim->v_half);
}

/* B.3; without bodies, v*^n is v^n */
static const double *stage_position_update(cs_sim *sim, const step_state *st)
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
static const double *stage_body_collision(cs_sim *sim, const step_state *st)
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
static const double *stage_velocity_full(cs_sim *sim, const step_state *st)
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
static const double *stage_body_friction(cs_sim *sim, const step_state *st)
{
    cs_body_friction(sim, st->dt);
    return NULL; /* checked */
}

/* B.8: inelastic repulsion and friction on the final velocity */
static const double *stage_self_friction(cs_sim *sim, const step_state *st)
{
    return repulsed(sim, cs_selfcol_repulse(sim, sim->x, sim->v_next, st->dt, false), sim->v_next);
}

static const struct {
    cs_stage stage;
    /* returns the velocity it made, for the runaway check; NULL where it
     * changed none or checked its own */
    stage_fn run;
} STEP_STAGES[] = {
    {CS_STAGE_SCRIPTED_VERTICES, stage_scripted_vertices},
    {CS_STAGE_WIND, stage_wind},
    {CS_STAGE_VELOCITY_HALF, stage_velocity_half},
    {CS_STAGE_SELF_REPULSION, stage_self_repulsion},
    {CS_STAGE_POSITION_UPDATE, stage_position_update},
    {CS_STAGE_BODY_COLLISION, stage_body_collision},
    {CS_STAGE_VELOCITY_FULL, stage_velocity_full},
    {CS_STAGE_BODY_FRICTION, stage_body_friction},
    {CS_STAGE_SELF_FRICTION, stage_self_friction},
};

/* True on every rank when every owned particle is finite everywhere. */
int cs_sim_step(cs_sim *sim, double dt)
{
    cs_par *par = sim->par;
    step_state st = {.dt = dt, .t1 = sim->t + dt,
                     .bodies = cs_plan_has(&sim->plan, CS_STAGE_BODY_COLLISION)};
    if (fabs(st.t1 - sim->frame_end) <= 1e-9 * dt)
        st.t1 = sim->frame_end; /* the frame's last step lands on its end */
    sim->half_dt = 0.5 * dt;
    /* x (owned and ghosts) is current here; v only where owned. One pass
     * keeps x^n and resets the modes (the ghosts' are never read). */
    release_scripts(sim, dt);
    CS_PARALLEL_FOR_LOCAL(par, i) {
        memcpy(sim->x_prev + 3 * i, sim->x + 3 * i, 3 * sizeof(double));
        sim->mode[i] = sim->is_free[i] ? CS_FREE : CS_FIXED;
    }
    cs_runaway_begin_step(sim, st.t1);
    for (size_t k = 0; k < sizeof STEP_STAGES / sizeof STEP_STAGES[0]; k++) {
        cs_stage stage = STEP_STAGES[k].stage;
        if (!cs_plan_has(&sim->plan, stage))
            continue;
        STAGE_BEGIN(sim, stage);
        const double *v = STEP_STAGES[k].run(sim, &st);
        if (v)
            cs_runaway_check(sim, v, stage);
        STAGE_END(sim, stage);
    }
    int not_finite = cs_runaway_not_finite(sim, sim->v_next); /* v^(n+1) taken too */
    sim->t = st.t1;
    return cs_runaway_end_step(sim, not_finite) ? CS_OK : CS_ERR_UNSTABLE;
}

/* One outer collision step of k time steps (Section 4): step A, k steps of
 * B, step C. The rewind scheme (Bridson et al. 2002) first runs the k steps
 * and, if step C would find a collision, goes back and tries again with k
 * halved, until k = 1. Returns CS_OK or CS_ERR_UNSTABLE. */
static int outer_step(cs_sim *sim, int k)
{
    cs_selfcol *sc = sim->selfcol;
    if (!sc) {
        for (int i = 0; i < k; i++)
            if (cs_sim_step(sim, sim->dt) != CS_OK)
                return CS_ERR_UNSTABLE;
        return CS_OK;
    }
    bool rewind = sim->def.self.scheme == CS_COLLISION_REWIND;
    size_t bytes = sizeof(double) * 3 * (size_t)sim->n;
    double t0 = sim->t;
    if (rewind) /* keep the start to come back to; x equals x_free here */
        memcpy(sim->v_rewind, sim->v, bytes);
    if (sim->nscripts > 0) /* where a hold in step C sets the scripts' clocks back to */
        memcpy(sim->script_lag_start, sim->script_lag, sizeof(double) * (size_t)sim->nscripts);
    for (;;) {
        STAGE_BEGIN(sim, CS_STAGE_REPULSION_PAIRS);
        cs_selfcol_find_pairs(sim, k * sim->dt);
        STAGE_END(sim, CS_STAGE_REPULSION_PAIRS);
        for (int i = 0; i < k; i++)
            if (cs_sim_step(sim, sim->dt) != CS_OK)
                return CS_ERR_UNSTABLE;
        if (rewind && k > 1) {
            STAGE_BEGIN(sim, CS_STAGE_COLLISIONS);
            long found = cs_selfcol_collide(sim, sim->t - t0, k, true);
            STAGE_END(sim, CS_STAGE_COLLISIONS);
            if (found > 0) {
                memcpy(sim->x, sc->x_free, bytes);
                memcpy(sim->v, sim->v_rewind, bytes);
                if (sim->nscripts > 0)
                    memcpy(sim->script_lag, sim->script_lag_start,
                           sizeof(double) * (size_t)sim->nscripts);
                sim->t = t0;
                sc->stats.rewinds++;
                /* the halves run one after another, each from its own start */
                int first = k / 2, status = outer_step(sim, first);
                if (status != CS_OK)
                    return status;
                return outer_step(sim, k - first);
            }
        }
        STAGE_BEGIN(sim, CS_STAGE_COLLISIONS);
        cs_selfcol_collide(sim, sim->t - t0, k, false);
        if (sc->conflict.found) { /* the same on every rank */
            STAGE_END(sim, CS_STAGE_COLLISIONS);
            return CS_ERR_SCRIPT;
        }
        cs_runaway_check(sim, sim->v, CS_STAGE_COLLISIONS);
        STAGE_END(sim, CS_STAGE_COLLISIONS);
        return cs_runaway_end_step(sim, cs_runaway_not_finite(sim, NULL)) ? CS_OK : CS_ERR_UNSTABLE;
    }
}

static bool adaptive_step(const cs_sim *sim)
{
    return !(sim->def.dt > 0) && sim->def.step_limit == CS_STEP_DAMPED;
}

/* The step for the rest of a frame: the frame's remaining time in equal
 * steps no longer than dt_safety times the stability limit at the current
 * positions (or the scene's fixed step). Returns the number of steps. */
static long steps_for(cs_sim *sim, double remaining)
{
    if (!adaptive_step(sim)) /* fixed: the step set at creation */
        return lround(remaining / sim->dt);
    double dt_max = sim->def.dt_safety * cs_step_limit_now(sim);
    double steps = ceil(remaining / fmin(dt_max, remaining) - 1e-9);
    if (!(steps >= 1))
        steps = 1;
    if (steps > CS_MAX_STEPS_PER_FRAME)
        steps = CS_MAX_STEPS_PER_FRAME;
    sim->dt = remaining / steps;
    return (long)steps;
}

int cs_sim_advance_frame(cs_sim *sim, cs_frame_stats *stats)
{
    double frame = 1.0 / sim->def.fps;
    double t_end = sim->t + frame;
    sim->frame_end = t_end;
    long steps = 0;
    long cg0 = sim->cg_iterations, contacts0 = sim->contacts;
    cs_selfcol_stats self0 = {0};
    if (sim->selfcol) {
        sim->selfcol->stats.max_zone = 0; /* the largest zone of this frame */
        self0 = sim->selfcol->stats;
    }
    int status = CS_OK;
    /* The outer collision loop: k_i time steps, then step C. Chunks never
     * straddle a frame end, so every frame ends collision-free. The step is
     * chosen afresh before each chunk, from the tension the cloth has then
     * (step_limit.c); the steps left divide the frame's remaining time. */
    bool adaptive = adaptive_step(sim);
    /* the last step lands on t_end (cs_sim_step), free of the steps'
     * round-off */
    long left = steps_for(sim, frame);
    while (left > 0 && status == CS_OK) {
        long chunk = left < sim->def.collision_steps ? left : sim->def.collision_steps;
        status = outer_step(sim, (int)chunk);
        steps += chunk;
        left -= chunk;
        if (left > 0 && adaptive && status == CS_OK)
            left = steps_for(sim, t_end - sim->t);
    }
    /* frame end: rank 0 gets the whole state (frames are written once),
     * the verifier counts, and the counters each rank kept for its own
     * particles and pairs are summed */
    {
        STAGE_BEGIN(sim, CS_STAGE_FRAME_END);
        cs_par_gather_root(sim->par, sim->x, 3);
        cs_par_gather_root(sim->par, sim->v, 3);
        STAGE_END(sim, CS_STAGE_FRAME_END);
    }
    long intersections = -1;
    if (status == CS_OK && cs_plan_has(&sim->plan, CS_STAGE_VERIFY)) {
        STAGE_BEGIN(sim, CS_STAGE_VERIFY);
        if (sim->par->rank == 0)
            intersections = cs_sim_count_intersections(sim);
        STAGE_END(sim, CS_STAGE_VERIFY);
    }
    double frame_end_t0 = cs_now();
    cs_par_begin(sim->par, CS_STAGE_FRAME_END);
    cs_selfcol_stats self = {0};
    if (sim->selfcol)
        self = sim->selfcol->stats;
    long sums[4] = {sim->contacts - contacts0, self.repulsion_pairs - self0.repulsion_pairs,
                    self.repulsions - self0.repulsions, self.collisions - self0.collisions};
    cs_par_sum_long(sim->par, sums, 4);
    double max_speed = 0;
    CS_FOR_OWNED(sim->par, i)
        max_speed = fmax(max_speed, cs_norm(sim->v + 3 * i));
    cs_par_max(sim->par, &max_speed, 1);
    sim->timing[CS_STAGE_FRAME_END].seconds += cs_now() - frame_end_t0; /* its second part */
    cs_par_report(sim->par, sim->timing, sim->timing_all, sim->comm_all, sim->rank_comm);
    if (stats) {
        memset(stats, 0, sizeof *stats);
        stats->steps = (int)steps;
        stats->dt = frame / (double)steps; /* the mean step */
        stats->cg_iterations = sim->cg_iterations - cg0;
        stats->body_contacts = sums[0];
        stats->max_speed = max_speed;
        if (sim->selfcol) { /* passes, zones and rewinds are the same on every rank */
            stats->repulsion_pairs = sums[1];
            stats->repulsions = sums[2];
            stats->collisions = sums[3];
            stats->collision_passes = self.passes - self0.passes;
            stats->impact_zones = self.zones - self0.zones;
            stats->max_zone_size = self.max_zone;
            stats->held_zones = self.held_zones - self0.held_zones;
            stats->projected_zones = self.projected_zones - self0.projected_zones;
            stats->rewinds = self.rewinds - self0.rewinds;
            stats->pair_searches = self.cache_searches - self0.cache_searches;
            stats->pair_traversals = self.cache_builds - self0.cache_builds;
        }
        stats->intersections = intersections;
        for (int sc = 0; sc < sim->nscripts; sc++)
            if (!sim->scripts[sc].released)
                stats->script_lag = fmax(stats->script_lag, sim->script_lag[sc]);
    }
    return status;
}
