/* step_limit.c: the largest time step the scheme of Section 3 allows.
 *
 * Steps B.1-B.6 take the elastic forces explicitly and the damping
 * implicitly. For a linearised system with mass M, elastic stiffness K and
 * damping D (both symmetric positive semi-definite) the step's
 * amplification matrix has spectral radius at most 1 exactly when
 *
 *     dt^2 K - 2 dt D  <=  4 M        (in the Loewner order).
 *
 * Without damping that is dt omega_max <= 2, the familiar limit; for one
 * spring of stiffness k, damping c and reduced mass m it is
 * dt <= (c + sqrt(c^2 + 4 k m)) / k, which for Table 1's overdamping
 * (c = 15 times critical) is about 30 times 2 / omega. The damping of
 * Section 3 acts along each spring only, so the stiffness a stretched
 * spring has across itself (its tension over its length, g = E (1/L0 -
 * 1/l)) is not damped and bounds the step like an undamped spring: a
 * stretched cloth needs smaller steps than a slack one. (The condition was
 * checked numerically against the amplification matrix's eigenvalues for
 * random M, K and rank-deficient D; docs/accuracy.md, "The damped step
 * limit".)
 *
 * The test used: drop the springs whose damping outweighs their stiffness
 * at this dt (removing a negative semi-definite term only raises the
 * largest eigenvalue) and bound the rest by Gershgorin's theorem,
 *     max_i (1 / m_i) sum_s w_s max(dt^2 k_s - 2 dt c_s, dt^2 |g_s|, 0) <= 4,
 * with w_s = 2 (the diagonal and the far particle's entry), or 1 where the
 * far end is pinned or scripted and so no unknown (counting it twice put
 * the twist's limit at the free particle beside its scripted corner, 24%
 * above the next row): a sufficient condition, evaluated at the current
 * positions before every outer step. The largest dt passing it is found
 * by bisection; each evaluation is a maximum over particles (and ranks),
 * so the step is the same at every thread and rank count. The undamped
 * limit from Lanczos iterations (2 / omega_max at the rest state, the
 * default step) stays a floor: the step never becomes smaller than the
 * default's. tests/test_step_limit.c checks the bound against the
 * spectrum itself.
 *
 * The default (time.step_limit: auto) takes the damped limit when the
 * cloth's damping makes it at least def.auto_min_gain times the undamped one
 * at rest, as Table 1's overdamping does (about 38 times): then a step
 * costs a little more (the bound before each outer step, more CG
 * iterations a solve) and a frame needs a fraction of the steps. Steps far
 * above the undamped limit are stable but less accurate where friction and
 * contact matter (the incline's analytic error grows past its 0.1%
 * tolerance at twice the undamped step); docs/accuracy.md, "The damped
 * step limit", measures the cost, and `undamped` keeps the small step.
 */
#include <math.h>
#include <stdlib.h>

#include "sim/internal.h"
#include "sim/par.h"
#include "sim/springs.h"

/* Lanczos iterations for the largest eigenvalue of M^-1 K */
enum { LANCZOS_STEPS = 60 };
/* bisections in log dt between brackets at most a frame apart: 2^-24 of
 * the ratio leaves the step within 1e-6 of the largest that passes */
enum { STEP_BISECTIONS = 24 };
/* a step is stable when the bound is at most this */
static const double STABLE_BOUND = 4;

typedef double (*step_bound_fn)(cs_sim *sim, double dt);

static double rest_bound(cs_sim *sim, double dt)
{
    return cs_springs_rest_step_bound(&sim->springs, sim->mass, sim->is_free, sim->n, dt);
}

/* The current positions' bound over the rows still in question
 * (sim->bound_rows, or every row while nbound_rows < 0). A failing dt
 * becomes the bisection's upper end, and a row that passes there passes
 * at every step still to be tried (springs.h), so only the rows that
 * failed stay in question: the bisection answers the same at every test,
 * and its later tests read a few rows instead of all of them (26 passes
 * over the springs an outer step before). */
static double current_bound(cs_sim *sim, double dt)
{
    const cs_springs *s = &sim->springs;
    bool listed = sim->nbound_rows >= 0;
    double bound = cs_springs_step_bound(s, sim->mass, sim->is_free, dt,
                                         listed ? sim->bound_rows : NULL, sim->nbound_rows,
                                         sim->bound_value);
    cs_par_max(sim->par, &bound, 1);
    if (bound > STABLE_BOUND && sim->bound_value) { /* dt fails: keep the rows above */
        int n = listed ? sim->nbound_rows : s->nrows, kept = 0;
        for (int k = 0; k < n; k++)
            if (sim->bound_value[k] > STABLE_BOUND)
                sim->bound_rows[kept++] = listed ? sim->bound_rows[k] : k;
        sim->nbound_rows = kept;
    }
    return bound;
}

/* The largest dt in [lo, hi] whose bound is at most 4; 0 when lo fails. */
static double largest_step(cs_sim *sim, step_bound_fn bound, double lo, double hi)
{
    if (!(lo > 0) || !(bound(sim, lo) <= STABLE_BOUND))
        return 0;
    if (bound(sim, hi) <= STABLE_BOUND)
        return hi;
    for (int it = 0; it < STEP_BISECTIONS; it++) {
        double mid = sqrt(lo * hi);
        if (bound(sim, mid) <= STABLE_BOUND)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

/* At the damped limit a scripted vertex moves at most this fraction of
 * script_length in a step. Uncapped, the damped step closed the pinch
 * between scripted plates (tests/data/scenes/pinch.yaml) by 6 thicknesses
 * a step, more than step C's zones could resolve: the run stopped with a
 * script conflict in frame 1, as it did at 1; at 0.5 and 0.25 it stays
 * intersection free with the plates on their keys (the undamped step moved
 * them 0.09 thickness). The half-million-triangle twist (ends at 1.7 m/s,
 * thickness 0.4 mm) gets a step of 6.0e-5 s at rest, 18 times its undamped one. */
static const double SCRIPT_STEP_FRACTION = 0.25;

/* The length a scripted vertex's step is measured against: the repulsion
 * thickness with self-collisions (what step A's pairs and step C's zones
 * resolve), else the shortest edge (what the springs resolve). */
static double script_length(const cs_sim *sim)
{
    double len = sim->def.self_collision ? sim->def.self.thickness : INFINITY;
    const cs_springs *s = &sim->springs;
    for (int k = 0; k < s->nedge; k++)
        len = fmin(len, s->rest_length[k]);
    return len;
}

double cs_step_limit_scripts(const cs_sim *sim, double t0, double t1)
{
    double fastest = 0;
    for (int s = 0; s < sim->nscripts; s++) {
        const cs_script_state *sc = sim->scripts + s;
        if (sc->released)
            continue;
        /* a script behind its keys runs on its own clock, faster (scripts.c) */
        double lag = sim->script_lag ? sim->script_lag[s] : 0;
        fastest = fmax(fastest, cs_motion_max_speed(&sc->motion, t0 - lag, t1, sc->radius) *
                                    (lag > 0 ? CS_SCRIPT_CATCH_UP_RATE : 1.0));
    }
    /* the undamped step is the floor, as for the damped limit itself: it
     * was the step for every scripted scene before the cap, and on the
     * 32 x 16 twist it moves the ends half a thickness a step, resolved */
    return fastest > 0 ? fmax(sim->script_reach / fastest, sim->def.dt_safety * sim->undamped_dt)
                       : INFINITY;
}

/* auto's choice. The projection friction method keeps the undamped step
 * whatever the gain, because the larger step breaks it: at the damped step
 * the rolling cloth sinks 4.5 mm into the incline, against under 1 mm at
 * the undamped one. */
static bool auto_takes_damped(cs_sim *sim)
{
    if (sim->def.friction_method != CS_FRICTION_IMPROVED) {
        sim->step_limit_why = "the projection friction method keeps the undamped step";
        return false;
    }
    bool gain = sim->damped_dt >= sim->def.auto_min_gain * sim->undamped_dt;
    sim->step_limit_why = gain ? "the gain is at least auto_min_gain" : "the gain is below auto_min_gain";
    return gain;
}

void cs_step_limit_init(cs_sim *sim)
{
    int n = sim->n;
    double bound = cs_springs_stiffness_bound(&sim->springs, sim->mass, sim->is_free, n);
    double lambda = bound > 0 ? cs_springs_max_eigenvalue(&sim->springs, sim->x, sim->mass,
                                                          sim->is_free, n, LANCZOS_STEPS)
                              : 0;
    if (!(lambda > 0) || lambda > bound)
        lambda = bound; /* Lanczos out of memory: Gershgorin's bound */
    sim->gershgorin_dt = bound > 0 ? 2.0 / sqrt(bound) : INFINITY;
    sim->script_reach = SCRIPT_STEP_FRACTION * script_length(sim);
    sim->undamped_dt = lambda > 0 ? 2.0 / sqrt(lambda) : INFINITY;
    /* Gershgorin's undamped step passes the damped test too (each term is
     * at most dt^2 k): the bracket's lower end */
    double frame = 1.0 / sim->def.fps;
    double damped = isfinite(sim->gershgorin_dt)
                        ? largest_step(sim, rest_bound, fmin(sim->gershgorin_dt, frame), frame)
                        : INFINITY;
    sim->damped_dt = fmax(sim->undamped_dt, damped);
    sim->step_limit = sim->def.step_limit;
    sim->step_limit_why = NULL;
    if (sim->step_limit == CS_STEP_AUTO)
        sim->step_limit = auto_takes_damped(sim) ? CS_STEP_DAMPED : CS_STEP_UNDAMPED;
    sim->stable_dt = sim->step_limit == CS_STEP_DAMPED ? sim->damped_dt : sim->undamped_dt;
}

double cs_step_limit_now(cs_sim *sim)
{
    if (!isfinite(sim->gershgorin_dt))
        return INFINITY; /* no springs */
    cs_springs_prepare(&sim->springs, sim->x); /* the tension at x */
    int nrows = sim->springs.nrows;
    if (sim->bound_capacity < nrows) { /* without the lists, every test reads every row */
        free(sim->bound_rows);
        free(sim->bound_value);
        sim->bound_rows = malloc(sizeof *sim->bound_rows * (size_t)nrows);
        sim->bound_value = malloc(sizeof *sim->bound_value * (size_t)nrows);
        sim->bound_capacity = sim->bound_rows && sim->bound_value ? nrows : 0;
        if (!sim->bound_capacity) {
            free(sim->bound_rows);
            free(sim->bound_value);
            sim->bound_rows = NULL;
            sim->bound_value = NULL;
        }
    }
    sim->nbound_rows = -1; /* every row in question */
    double frame = 1.0 / sim->def.fps;
    double damped = largest_step(sim, current_bound, fmin(sim->gershgorin_dt, frame), frame);
    return fmax(sim->undamped_dt, damped);
}
