/* internal.h: the simulation state, private to sim/. Particle arrays are
 * flat (3 doubles per particle) and free of bookkeeping. */
#ifndef CS_INTERNAL_H
#define CS_INTERNAL_H

#include "sim/par.h"
#include "sim/sim.h"
#include "sim/selfcol.h"
#include "sim/shares.h"
#include "sim/springs.h"
#include "sim/vec3.h"

/* body.c: a body posed once for many queries */
/* A body's frame at one time: for many queries at that time (a step asks
 * each body about every point near it), computed once. */
typedef struct cs_body_pose {
    double R[9], c[3], velocity[3], omega[3];
    bool unrotated; /* R is exactly the identity: queries skip the products */
} cs_body_pose;
void cs_body_def_pose(const cs_body_def *b, double t, cs_body_pose *pose);
/* cs_body_def_phi and cs_body_def_velocity at a pose: the same numbers */
double cs_body_posed_phi(const cs_body_def *b, const cs_body_pose *pose, const double x[3],
                         double grad[3]);
void cs_body_posed_velocity(const cs_body_pose *pose, const double x[3], double v[3]);
/* The body's Coulomb coefficient at time t: `friction`, or its schedule
 * evaluated at t (see cs_body_def.friction_keys). */
double cs_body_def_friction(const cs_body_def *b, double t);
/* Velocity at time t of the body material point at world position x. */
void cs_body_def_velocity(const cs_body_def *b, double t, const double x[3], double v[3]);

/* What the solver may change about a particle's velocity. */
enum { CS_FIXED = 0, CS_FREE = 1, CS_CONTACT = 2 };

typedef struct cs_script_state {
    cs_motion motion;     /* keys owned by the sim */
    double rotation0[9];  /* R(0), to express vertices in the frame */
    int nvertices;
    int *vertices;        /* global particle indices */
    double *local;        /* 3 per vertex: R(0)^T (x0 - c(0)) */
    double radius;        /* the largest |local|: the farthest vertex */
    double release_time;  /* > 0: let go then (cs_vertex_script) */
    bool released;
} cs_script_state;

/* motion.c: a bound on the speed of any point within r of the motion's
 * centre at any time in [t0, t1]: |dc/dt| + |omega| r at its fastest */
double cs_motion_max_speed(const cs_motion *m, double t0, double t1, double r);

/* A script that step C held back runs at this multiple of its speed until
 * its clock is the simulation's again (scripts.c; runaway.c bounds it). */
static const double CS_SCRIPT_CATCH_UP_RATE = 2.0;

/* runaway.c: what instability detection knows (see there). */
typedef struct cs_runaway {
    double initial_speed, wave_speed; /* from the scene, fixed at creation */
    double limit, limit2;             /* this step's bound on speed, m/s */
    int stage;                        /* first stage past it; -1: none */
    double speed;                     /* the speed seen there (inf: NaN) */
} cs_runaway;

typedef struct cs_cloth_state {
    char *name;
    int offset;
    cs_trimesh *mesh;
} cs_cloth_state;

/* Threads share owned particles in blocks of this many; sums over them
 * are taken block by block in block order (the same at any thread count).
 * Small, so that the threads' shares of blocks hold about as many
 * particles: with 1,024, the 50 x 50 sheet's 2,601 particles made 3 blocks,
 * 2,048 rows for one thread and 553 for the other, and CG's passes waited
 * on the first. */
enum { CS_BLOCK = 64 };

typedef struct cs_cg_work {
    double *z, *r, *y, *p, *q;
    double *explicit_z;          /* the explicit update CG starts from */
    double *block;               /* 6 per particle: the preconditioner's 3 x 3 inverse */
    /* the damping responses of B.1's last solve and of the one before,
     * and B.5's less B.1's of the same step, also for the last two steps
     * (cs_cg_solve starts from a blend of the two) */
    double *warm_half, *warm_full_less_half, *warm_half_before, *warm_full_less_half_before;
    double *partial;  /* 3 per block: two partial sums and a partial maximum */
    double *inv_mass; /* 1 / m per particle: multiplies where the solve divided */
} cs_cg_work;

struct cs_sim {
    cs_sim_def def;               /* arrays below replace the def's pointers */
    cs_plan plan;
    int n;                        /* particles */
    double *x, *v, *mass;
    unsigned char *is_free;       /* 0 for pinned and scripted particles */
    unsigned char *mode;          /* CS_FIXED / CS_FREE / CS_CONTACT this step */

    int ncloths;
    cs_cloth_state *cloths;
    int nscripts;
    cs_script_state *scripts;
    double *script_x, *script_v;  /* 3 per particle: targets at t^{n+1} */
    int *script_of;               /* per particle: its script, or -1 */
    /* per script: how far (s) its clock is behind the simulation's, after
     * step C held it back (selfcol_collide.c), and the same at the outer
     * step's start; a script behind runs at twice the speed until it is
     * back on time (scripts.c's cs_script_targets) */
    double *script_lag, *script_lag_start;
    int nbodies;
    cs_body_def *bodies;          /* motion keys owned by the sim */
    cs_springs springs;           /* those this rank computes */
    int nsprings;                 /* edge and bending springs of the whole scene */

    /* step scratch */
    double *x_prev, *v_half, *v_star, *v_next, *force, *v0, *rhs;
    cs_cg_work cg;
    cs_shares shares;             /* the owned rows' split among the threads */
    /* body stages only */
    double *contact_normal;       /* 3 per particle */
    int *contact_body;            /* -1 when not in contact */
    cs_body_pose *body_pose;      /* per body, at the end of the step B.4 and
                                     B.7 are in (computed once per step) */
    /* self-collision stages only */
    cs_selfcol *selfcol;
    double *v_rewind;             /* rewind scheme: velocities at the outer step's start */
    /* wind stage only */
    double *wind_normal;          /* 3 per particle, area weighted unit normal */
    double *wind_area;            /* 1 per particle */

    double t, dt, half_dt;        /* dt / 2 of the current solve (h is the
                                   * paper's repulsion thickness) */
    double frame_end;             /* advance_frame's end time: a step that
                                   * lands within round-off of it lands on it */
    cs_step_limit step_limit;     /* def.step_limit with auto resolved */
    const char *step_limit_why;   /* what decided auto (NULL: not auto) */
    double stable_dt;             /* the limit step_limit names, at rest */
    double damped_dt;             /* the damped scheme's limit at rest (step_limit.c) */
    double undamped_dt;           /* 2 / omega_max, omega_max^2 by Lanczos */
    double gershgorin_dt;         /* the same from Gershgorin's bound (smaller) */
    double script_reach;          /* how far a scripted vertex may move in a
                                   * step at the damped limit (step_limit.c) */
    /* the damped limit's bisection (step_limit.c): the rows still in
     * question (-1: all) and each one's bound at the last step tried */
    int *bound_rows, nbound_rows, bound_capacity;
    double *bound_value;
    cs_par *par;                  /* ownership, ghosts, messages (Section 7) */
    unsigned char *active;        /* free and owned here: bodies act on these */
    cs_stage_timing timing[CS_STAGE_COUNT];
    /* rank 0 after a frame: over all ranks (see cs_sim_stage_timing) */
    cs_stage_timing timing_all[CS_STAGE_COUNT];
    cs_comm_stats comm_all[CS_STAGE_COUNT];
    cs_comm_stats *rank_comm;     /* per rank totals */
    size_t stage_bytes[CS_STAGE_COUNT];
    long cg_iterations, contacts;
    cs_runaway runaway;
};

/* mesh.c: sorts n (a, b) integer pairs lexicographically and drops the
 * repeats; returns how many are left (edges of a mesh, halo entries). */
int cs_sort_unique_pairs(int *pairs, int n);

/* cg.c: solves P (M - (dt/2) D) P z = P (rhs - (M - (dt/2) D) v0) for v = v0 + z,
 * where P projects out fixed velocities and contact normals, over all
 * ranks (v0's ghosts are refreshed first; v is written where owned).
 * warm and warm_before (3 per particle each, or both NULL) hold the
 * damping responses of the last two solves of the same kind, less base's
 * (NULL: zero), and base plus their blend is added to the start; they
 * shift by one, warm receiving this one's response less base. With
 * check_stage >= 0, v is that stage's velocity and the last pass checks it
 * for a runaway (cs_runaway_check's work, folded in).
 * Returns the iteration count, the same on every rank. */
int cs_cg_solve(cs_sim *sim, const double *v0, const double *rhs, double *v, const double *base,
                double *warm, double *warm_before, int check_stage);
/* out = (M - (dt/2) D) v, D the damping (and wind drag) velocity Jacobian. */
void cs_system_apply(const cs_sim *sim, const double *v, double *out);
/* acc += the implicit part of the wind's linear normal drag on particle i */
static inline void cs_wind_drag_row(const cs_sim *sim, int i, const double *v, double acc[3])
{
    const double *nrm = sim->wind_normal + 3 * i;
    cs_axpy(-sim->def.wind.drag * sim->wind_area[i] * cs_dot(nrm, v + 3 * i), nrm, acc);
}
/* acc += (D v)_i for owned row r, particle i: its springs' damping, then
 * the wind's drag. Inline, so that a pass over the rows does the rest of a
 * particle's work with it. */
static inline void cs_damping_row(const cs_sim *sim, int r, int i, const double *v,
                                  double acc[3])
{
    cs_springs_damping_row(&sim->springs, r, v, acc);
    if (sim->wind_normal)
        cs_wind_drag_row(sim, i, v, acc);
}

/* runaway.c: init after the step size and scripts are known; each step
 * begins with the bound at its end time, checks v after each stage that
 * makes a velocity, and ends with one reduction (false: unstable). */
void cs_runaway_init(cs_sim *sim);
double cs_runaway_limit(const cs_sim *sim, double t);
void cs_runaway_begin_step(cs_sim *sim, double t1);
void cs_runaway_check(cs_sim *sim, const double *v, cs_stage stage);
/* The check folded into a stage's own pass over the particles it changed
 * (the others were checked by an earlier stage and are unchanged): each
 * particle's velocity through cs_speed_seen (worst and nan_seen reduced
 * with max and ||), then one cs_runaway_note. */
static inline void cs_speed_seen(const double vi[3], double *worst, int *nan_seen)
{
    double s2 = vi[0] * vi[0] + vi[1] * vi[1] + vi[2] * vi[2];
    if (s2 != s2)
        *nan_seen = 1;
    else if (s2 > *worst)
        *worst = s2;
}
void cs_runaway_note(cs_sim *sim, cs_stage stage, double worst, int nan_seen);
/* not_finite: cs_runaway_not_finite's answer */
bool cs_runaway_end_step(cs_sim *sim, int not_finite);
/* Whether any owned x or v is not finite; with v_next, v takes it first,
 * in the same pass (the step's end) */
int cs_runaway_not_finite(cs_sim *sim, const double *v_next);

/* step_limit.c: the stability limits at the rest state (stable_dt,
 * damped_dt, undamped_dt, gershgorin_dt), and the damped limit at the
 * current positions
 * (collective: every rank calls it at the same point). */
void cs_step_limit_init(cs_sim *sim);
double cs_step_limit_now(cs_sim *sim);
/* The moving scripts' cap on the damped limit's step: the step in which a
 * scripted vertex moves script_reach at the scripts' fastest over (t0,
 * t1), but never below dt_safety times the undamped limit; INFINITY when
 * no script moves then */
double cs_step_limit_scripts(const cs_sim *sim, double t0, double t1);

/* scripts.c: the targets of scripted vertices at the end t1 of a step of
 * dt (script_x, script_v), at each script's own time t1 - lag */
void cs_script_targets(cs_sim *sim, double t1, double dt);
/* scripts whose release time has come let their vertices go, at the start
 * of a step */
void cs_scripts_release(cs_sim *sim, double dt);
/* the vertices of scripts with a release time still to come are held
 * (hold) or, while the step limit is computed for the whole run, free */
void cs_scripts_hold_releasable(cs_sim *sim, bool hold);

/* wind.c: area-weighted vertex normals and a third of the adjacent area
 * at positions x (wind_normal, wind_area), for the drag */
void cs_wind_geometry(cs_sim *sim, const double *x);
/* The wind at point p and time t (the +y axis is up in every scene). */
void cs_wind_at(const cs_wind_def *w, const double p[3], double t, double out[3]);
/* The fastest wind cs_wind_at can give anywhere, at any time. */
double cs_wind_max_speed(const cs_wind_def *w);

/* contact.c: Section 6. */
void cs_gamma(const double v[3], const double N[3], const double vb[3], double mu,
              double out[3]);
/* B.4; checks the velocities it makes for a runaway */
void cs_body_collide(cs_sim *sim, double dt);
/* B.7; checks the velocities it changes for a runaway */
void cs_body_friction(cs_sim *sim, double dt);

#endif
