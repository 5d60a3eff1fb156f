/* sim.h: the public face of the simulation core.
 *
 * The core is plain C11 and knows no files and no pixels. A caller fills the
 * definition structs below (starting from the cs_default_* functions, which
 * hold the paper's Table 1), creates a cs_sim, advances it frame by frame and
 * reads positions, counters and the timing table back.
 *
 * Units are SI throughout: metres, seconds, kilograms, newtons, radians.
 */
#ifndef CS_SIM_H
#define CS_SIM_H

#include <stdbool.h>
#include <stddef.h>

#include "common/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Section 7: the ranks that share a simulation, an MPI communicator named
 * without <mpi.h> (MPI stays inside sim/par.c): CS_COMM_WORLD
 * (MPI_COMM_WORLD), CS_COMM_SELF (this process alone), CS_COMM_NONE
 * (MPI_COMM_NULL: one rank, no MPI call), or any other communicator c as
 * MPI's own integer handle for it, MPI_Comm_c2f(c) (never negative). */
typedef int cs_comm;
#define CS_COMM_WORLD (-1)
#define CS_COMM_SELF (-2)
#define CS_COMM_NONE (-3)

/* ---------------------------------------------------------------- status */

/* Every fallible call returns CS_OK or a negative cs_status (CS_ERR_INVALID,
 * CS_ERR_NOMEM, CS_ERR_UNSTABLE, CS_ERR_SCRIPT) and, where a message buffer
 * is given, a sentence that says what was wrong. */

/* -------------------------------------------------------------- geometry */

/* A triangle mesh: nv vertices (3 doubles each), nt triangles (3 ints each). */
typedef struct cs_trimesh {
    int nv, nt;
    double *x;
    int *tri;
} cs_trimesh;

cs_trimesh *cs_trimesh_create(int nv, int nt);
void cs_trimesh_destroy(cs_trimesh *mesh);
/* The mean length of the triangles' edges (an edge of two triangles counted
 * twice); 0 without triangles. */
double cs_trimesh_mean_edge(const cs_trimesh *mesh);

/* A rectangle of size[0] x size[1] metres split into res[0] x res[1] quads
 * (two triangles each, diagonals alternating so the grid has no preferred
 * shear direction). It lies in the local x-z plane centred at the origin
 * (normal +y); rotate (a unit quaternion w,x,y,z) then center place it.
 * Vertex (i, j), i along x and j along z, has index j * (res[0] + 1) + i. */
cs_trimesh *cs_trimesh_create_grid(const double size[2], const int res[2],
                                   const double rotate[4], const double center[3]);


/* Values on one mesh's vertices carried to another's through their shapes
 * (sim/resample.c): each vertex of `to` takes the nearest point of `from`'s
 * surface, a triangle and barycentric weights, and values (3 a vertex,
 * positions or velocities) are interpolated there. Made from two rest
 * shapes, it starts a cloth from a state of the same cloth at another
 * resolution (clothsim run --start-from). Returns NULL when out of memory
 * or `from` has no triangle; *worst: the largest distance of a `to` vertex
 * from `from`'s surface, in metres. */
typedef struct cs_surface_map cs_surface_map;
cs_surface_map *cs_surface_map_create(const cs_trimesh *from, const cs_trimesh *to,
                                      double *worst);
/* to_values: 3 per vertex of the `to` mesh the map was made for */
void cs_surface_map_apply(const cs_surface_map *map, const cs_trimesh *from,
                          const double *from_values, double *to_values);
void cs_surface_map_destroy(cs_surface_map *map);
/* ---------------------------------------------------------------- motion */

/* One key of a keyframed rigid motion: at `time` the object's frame sits at
 * `position` with orientation `rotation` (unit quaternion w,x,y,z).
 * Between keys position is interpolated linearly and rotation by slerp, so
 * linear and angular velocity are constant on each interval. */
typedef struct cs_keyframe {
    double time;
    double position[3];
    double rotation[4];
} cs_keyframe;

typedef enum cs_motion_kind {
    CS_MOTION_STATIC = 0,   /* stays at position/rotation */
    CS_MOTION_CONSTANT,     /* constant linear and angular velocity */
    CS_MOTION_KEYFRAMES,    /* piecewise linear / slerp between keys */
} cs_motion_kind;

/* A rigid motion of a frame over time. A point p given in the frame's local
 * coordinates is at  c(t) + R(t) p  in the world at time t. */
typedef struct cs_motion {
    cs_motion_kind kind;
    double position[3];          /* c(0) */
    double rotation[4];          /* R(0) as a unit quaternion w,x,y,z */
    double velocity[3];          /* CS_MOTION_CONSTANT: dc/dt */
    double angular_velocity[3];  /* CS_MOTION_CONSTANT: world axis * rad/s */
    int nkeys;                   /* CS_MOTION_KEYFRAMES */
    const cs_keyframe *keys;     /* sorted by time; copied by cs_sim_create */
} cs_motion;

/* Rotations as unit quaternions (w, x, y, z), shared with the importer. */
void cs_quat_multiply(const double a[4], const double b[4], double out[4]);
/* Degrees about world x, then y, then z: R = Rz Ry Rx. */
void cs_quat_from_euler_degrees(const double degrees[3], double out[4]);
/* The shortest-arc rotation taking +y onto the unit vector n. */
void cs_quat_from_y_to(const double n[3], double out[4]);
void cs_quat_rotate(const double q[4], const double v[3], double out[3]);

/* The identity motion: static at the origin. */
cs_motion cs_motion_static(void);

/* Pose at time t: rotation matrix R (row-major 3x3), origin c, and the
 * frame's linear velocity dc/dt and angular velocity omega. Any output
 * pointer may be NULL. */
void cs_motion_pose(const cs_motion *m, double t, double R[9], double c[3],
                    double velocity[3], double omega[3]);

/* ---------------------------------------------------------------- bodies */

typedef enum cs_body_shape {
    CS_BODY_PLANE = 0,   /* local plane y = 0, outside is +y */
    CS_BODY_SPHERE,      /* radius, centred at the local origin */
    CS_BODY_BOX,         /* half_extents, centred at the local origin */
    CS_BODY_CYLINDER,    /* radius, half_height, axis local y, capped */
    CS_BODY_MESH,        /* a level set from a mesh: phi_fn is required */
    CS_BODY_SHAPE_COUNT
} cs_body_shape;

/* A signed distance queried in the body's local frame: returns phi and writes
 * the unit gradient. Grid bodies (level sets from meshes) plug in here. It
 * must be safe to call from several threads at once (the body stages visit
 * points in parallel). */
typedef double (*cs_body_phi_fn)(const void *data, const double p[3], double grad[3]);

/* One key of a body's friction schedule: at `time` (s) the Coulomb
 * coefficient is `friction` (>= 0). */
typedef struct cs_friction_key {
    double time;
    double friction;
} cs_friction_key;

/* The most keys a friction schedule holds (kept in the definition by value,
 * so that copying a body copies its schedule). */
#define CS_BODY_MAX_FRICTION_KEYS 16

typedef struct cs_body_def {
    const char *name;
    cs_body_shape shape;
    double radius;
    double half_extents[3];
    double half_height;
    double friction;          /* Coulomb coefficient mu, when nfriction_keys == 0 */
    /* Friction that changes over time: with nfriction_keys > 0 (at most
     * CS_BODY_MAX_FRICTION_KEYS), mu(t) is piecewise linear between the
     * keys, which must have strictly increasing times and friction >= 0;
     * the first key's value holds before it and the last's after it, and
     * `friction` is unused. A pure function of time, so it is part of the
     * definition, not of the state a checkpoint stores. */
    int nfriction_keys;
    cs_friction_key friction_keys[CS_BODY_MAX_FRICTION_KEYS];
    /* Collision offset, m: cloth vertices are kept this far outside the
     * surface (phi >= offset), so that a coarse cloth resting on a curved
     * or detailed body does not let the surface poke through between its
     * vertices. 0: vertices on the surface itself (the paper). */
    double offset;
    cs_motion motion;         /* where the local frame is over time */
    /* Optional: a user distance function replacing the analytic shape. */
    cs_body_phi_fn phi_fn;
    const void *phi_data;
    /* With phi_fn: a local box outside which phi > 0, so that the body is
     * only asked about points near it; without one, about every point. */
    bool phi_bounded;
    double phi_min[3], phi_max[3];
} cs_body_def;

cs_body_def cs_default_body_def(void);

/* Signed distance and unit gradient of a body at world point x, time t. */
double cs_body_def_phi(const cs_body_def *b, double t, const double x[3], double grad[3]);

/* ---------------------------------------------------------------- cloth */

/* The paper's Table 1. Stiffnesses are Young's moduli of the spring force
 * law F = E (|u|/|u0| - 1), so they are forces (N). */
typedef struct cs_cloth_material {
    double edge_stiffness;     /* E_e, N           (4.14) */
    double edge_overdamping;   /* xi_e             (15)   */
    double bend_stiffness;     /* E_b, N           (0.41) */
    double bend_overdamping;   /* xi_b             (8)    */
    double node_mass;          /* kg per vertex    (1e-6), used when density == 0 */
    double density;            /* kg/m^2 areal density; > 0 overrides node_mass */
} cs_cloth_material;

cs_cloth_material cs_default_cloth_material(void);

/* A set of cloth vertices whose positions are prescribed: pinned (static
 * motion) or moved by a script. Vertex positions at time 0 are taken as the
 * frame's local coordinates relative to motion.position, i.e. a vertex at
 * world x0 is at c(t) + R(t) R(0)^T (x0 - c(0)) at time t. */
typedef struct cs_vertex_script {
    int nvertices;
    const int *vertices;      /* indices into the cloth's mesh */
    cs_motion motion;
    /* > 0: the vertices are let go at this time (s), at the first step that
     * starts then or later, with the script's velocity, and move freely
     * after; 0: held for the whole run */
    double release_time;
} cs_vertex_script;

typedef struct cs_cloth_def {
    const char *name;
    const cs_trimesh *mesh;   /* copied by cs_sim_create */
    cs_cloth_material material;
    double velocity[3];       /* initial velocity of every vertex */
    int nscripts;
    const cs_vertex_script *scripts;
} cs_cloth_def;

/* --------------------------------------------------------------- the run */

/* How the automatic step is bounded. */
typedef enum cs_step_limit {
    CS_STEP_UNDAMPED = 0, /* dt_safety x 2 / omega_max: the elastic forces alone, fixed */
    CS_STEP_DAMPED,       /* dt_safety x the damped scheme's limit at the current
                           * tension, chosen before every outer step (step_limit.c):
                           * larger steps, less accurate contact and friction */
    CS_STEP_AUTO,         /* damped where the cloth's damping makes its limit at rest
                           * several times the undamped one, else undamped */
} cs_step_limit;

typedef enum cs_friction_method {
    CS_FRICTION_IMPROVED = 0,  /* Section 6: crossing point, Gamma, v_NP */
    CS_FRICTION_PROJECTION,    /* Bridson et al. 2003: project along normal */
} cs_friction_method;

/* Linear drag along the normal (Section 8): each vertex feels
 * F = -drag * area_i * ((v - wind(p, t)) . n) n, with area_i a third of the
 * area of its triangles, so drag has units N s / m^3. A uniform wind only
 * carries a leaf: the drag's centre is its centre of mass, so nothing turns
 * it. The paper's leaves "flutter" because their wind differs across them:
 * it keeps "a high wind speed near the ground" (ground_boost, fading
 * linearly to none at ground_height), and a scene may add gusts, an
 * Arnold-Beltrami-Childress flow (divergence-free, like air at these
 * speeds) of wavelength gust_length whose phases drift with gust_period;
 * gust is the RMS of each of its components. */
typedef struct cs_wind_def {
    double velocity[3];
    double drag;
    double ground_boost[3];  /* added at y <= 0, fading to 0 at ground_height */
    double ground_height;    /* m, > 0 (default 1) */
    double gust;             /* m/s, >= 0 (default 0: no gusts) */
    double gust_length;      /* m, > 0 (default 1) */
    double gust_period;      /* s, > 0 (default 2) */
} cs_wind_def;

/* Self-collision (Sections 4 and 5). Defaults from Table 1. */
typedef enum cs_collision_scheme {
    CS_COLLISION_FIXED = 0,   /* the paper: fixed k_i, never rewind */
    CS_COLLISION_REWIND,      /* Bridson et al. 2002: on a collision in step C,
                                 rewind and retry with k_i halved, down to 1 */
} cs_collision_scheme;

/* An impact zone holding vertices of two prescribed motions (two scripts,
 * a pin and a script), which no rigid motion can follow. */
typedef enum cs_script_zones {
    CS_SCRIPT_ZONES_FOLLOW = 0, /* the scripts go on exactly; the zone's free
                                   vertices are projected off the collisions
                                   around them (selfcol_project.c); where no
                                   answer exists the run stops and says so */
    CS_SCRIPT_ZONES_HOLD,       /* the zone stays where it was collision
                                   free and its scripts wait (they lag, as
                                   the summary reports) */
} cs_script_zones;

/* Step A's broad phase (docs/performance.md, "Step A's boxes along
 * the path"). */
typedef enum cs_pair_pruning {
    CS_PRUNING_SPEED = 0, /* the paper's non-aggressive pruning: a particle's
                             box grows by its speed relative to the cloth's
                             mean times the span, along all three axes */
    CS_PRUNING_PATH,      /* the box holds the particle's straight path
                             relative to the mean over the span: only pairs
                             whose straight paths come within h are kept */
} cs_pair_pruning;

typedef struct cs_self_collision_def {
    double thickness;          /* h, repulsion thickness, m          (0.01) */
    double stiffness;          /* k of Eq. 1, repulsion spring constant (30) */
    double friction;           /* cloth-cloth Coulomb coefficient       (0.3) */
    double edge_flip_epsilon;  /* history rule for edge/edge: flip when
                                  s0 . s < epsilon (0 aggressive, 0.9
                                  conservative)                         (0.5) */
    int zone_iterations;       /* step C passes before impact zones      (8) */
    cs_collision_scheme scheme;
    cs_script_zones script_zones; /* zones across scripts           (follow) */
    cs_pair_pruning pruning;   /* step A's broad phase              (speed) */
    bool verify;               /* count intersecting triangle pairs at each
                                  frame end (an independent check)  (false) */
} cs_self_collision_def;

cs_self_collision_def cs_default_self_collision_def(void);

typedef struct cs_sim_def {
    double gravity[3];
    double fps;                /* frames per second of output */
    double dt;                 /* > 0: fixed step; 0: automatic from stability */
    double dt_safety;          /* fraction of the stability limit used (auto) */
    cs_step_limit step_limit;  /* which limit (auto) */
    double auto_min_gain;      /* auto takes the damped limit when it is at
                                * least this many times the undamped one */
    int collision_steps;       /* k_i: time steps per outer collision loop */
    double cg_tolerance;       /* m/s, max norm of the velocity residual */
    int cg_max_iterations;
    cs_friction_method friction_method;
    bool bodies_enabled;       /* effects: body collisions and friction */
    bool wind_enabled;         /* effects: wind drag */
    bool self_collision;       /* effects: repulsions and collisions */
    cs_self_collision_def self;
    cs_wind_def wind;
    int ncloths;
    const cs_cloth_def *cloths;
    int nbodies;
    const cs_body_def *bodies;
    /* Section 7: the ranks that share the simulation (CS_COMM_WORLD by
     * default). Every rank makes the same calls with the same definition.
     * Without MPI initialised, or with CS_COMM_NONE, it is one rank and
     * makes no MPI call. */
    cs_comm comm;
    /* Only the plan and the step size are wanted (clothsim run --plan):
     * particles, masses and springs are built for Lanczos, and nothing the
     * step needs (scratch, solver, contacts, self-collision, partition) is
     * allocated; such a simulation cannot advance. */
    bool plan_only;
} cs_sim_def;

cs_sim_def cs_default_sim_def(void);

/* ------------------------------------------------------- plan and timing */

/* The stages of a time step, of an outer collision step and of a frame.
 * The values name them (and index timing arrays and stored totals); the
 * order they run in is the stage table's (sim/stages.c), cs_stage_in_order.
 * A plan holds only the ones the scene calls for; the others are neither
 * run nor allocated. */
typedef enum cs_stage {
    CS_STAGE_REPULSION_PAIRS = 0,   /* A: repulsion pairs and their history */
    CS_STAGE_SCRIPTED_VERTICES,     /* prescribed positions and velocities */
    CS_STAGE_WIND,                  /* normals and areas for wind drag */
    CS_STAGE_VELOCITY_HALF,         /* B.1 backward Euler half step (CG) */
    CS_STAGE_SELF_REPULSION,        /* B.2 inelastic and elastic repulsion */
    CS_STAGE_POSITION_UPDATE,       /* B.3 */
    CS_STAGE_BODY_COLLISION,        /* B.4 crossing point, Gamma */
    CS_STAGE_VELOCITY_FULL,         /* B.5 projected solve (CG), B.6 */
    CS_STAGE_BODY_FRICTION,         /* B.7 Gamma on v_NP */
    CS_STAGE_SELF_FRICTION,         /* B.8 inelastic repulsion and friction */
    CS_STAGE_COLLISIONS,            /* C: continuous collisions, impact zones */
    CS_STAGE_VERIFY,                /* intersecting triangle pairs at frame end */
    CS_STAGE_FRAME_END,             /* gathering the frame, summing counters over ranks */
    CS_STAGE_COUNT
} cs_stage;

/* The i-th stage of the table, 0 <= i < CS_STAGE_COUNT, in the order the
 * stages run (CS_STAGE_COUNT outside that range). */
cs_stage cs_stage_in_order(int i);
const char *cs_stage_name(cs_stage stage);
const char *cs_stage_description(cs_stage stage);
/* What a scene needs for the stage to be in its plan ("always",
 * "effects.self_collision", ...). */
const char *cs_stage_condition(cs_stage stage);
/* When the stage runs ("each time step", ...). */
const char *cs_stage_when(cs_stage stage);
/* The memory a run of this many particles will need at its peak beyond
 * the setup, bytes (an estimate from measurements, with a margin): over its
 * first frames, so that a scene too large for the machine is refused
 * before anything is allocated, or, with in_contact, once the cloth lies
 * on itself and step A's pair lists have grown (clothsim run --plan). */
double cs_sim_estimate_bytes(double particles, bool self_collision, bool in_contact);

typedef struct cs_plan {
    int nstages;
    cs_stage stages[CS_STAGE_COUNT];
} cs_plan;

/* Inline: the stages ask it, and plan.c, which reads the stage table,
 * lies above them. */
static inline bool cs_plan_has(const cs_plan *plan, cs_stage stage)
{
    for (int i = 0; i < plan->nstages; i++)
        if (plan->stages[i] == stage)
            return true;
    return false;
}

typedef struct cs_stage_timing {
    double seconds;
    long calls;
} cs_stage_timing;

/* Messages a stage sent: time spent in communication calls (included in
 * the stage's seconds), bytes and messages sent. */
typedef struct cs_comm_stats {
    double seconds;
    long bytes, messages;
} cs_comm_stats;

/* Counters for one frame. */
typedef struct cs_frame_stats {
    int steps;
    double dt;
    long cg_iterations;
    long body_contacts;        /* particle-steps in contact with a body */
    double max_speed;          /* m/s at the end of the frame */
    /* self-collision (zero when it is off) */
    long repulsion_pairs;      /* pairs found by step A, summed over outer steps */
    long repulsions;           /* pair impulses applied in B.2 and B.8 */
    long collisions;           /* colliding pairs found by step C */
    long collision_passes;     /* step C iterations */
    long impact_zones;         /* zones formed */
    long max_zone_size;        /* particles in the largest zone */
    long held_zones;           /* zones spanning two scripts, held where collision free
                                  (script_zones: hold) */
    long projected_zones;      /* zones spanning two scripts whose free vertices
                                  were projected around them (script_zones: follow) */
    double script_lag;         /* s: the most any script is behind its keys at
                                  the frame's end (0 unless held) */
    long rewinds;              /* outer steps redone (rewind scheme) */
    long pair_searches;        /* searches of steps A and C */
    long pair_traversals;      /* of them, those that traversed the trees */
    long intersections;        /* verifier at frame end; -1 when not asked */
} cs_frame_stats;

/* ------------------------------------------------------------ simulation */

typedef struct cs_sim cs_sim;

/* Limits shared by every way a scene can ask for frames and steps: a frame
 * index fits an int, and a step so small that one frame needs more steps
 * than this is a mistake (time.dt of 1e-12, a stiffness of 1e308), refused
 * at creation rather than run for ever. */
#define CS_MAX_FRAMES 100000000
#define CS_MAX_STEPS_PER_FRAME 10000000

/* Creates the simulation: CS_OK and *out, or CS_ERR_INVALID (a definition
 * that cannot run, such as a step so small a frame would need more than
 * CS_MAX_STEPS_PER_FRAME) or CS_ERR_NOMEM, with why in err. A fixed step
 * above cs_sim_stable_dt is allowed (the limit is a sufficient condition,
 * not a necessary one); callers should warn, and cs_sim_runaway reports a
 * step that does blow up. */
int cs_sim_create_checked(const cs_sim_def *def, cs_sim **out, char *err, size_t errlen);
/* The same; on failure returns NULL and writes why into err. */
cs_sim *cs_sim_create(const cs_sim_def *def, char *err, size_t errlen);
void cs_sim_destroy(cs_sim *sim);

/* Advances one frame (1/fps seconds). Returns CS_OK or CS_ERR_UNSTABLE,
 * the same on every rank. A collective call: afterwards rank 0 holds every
 * particle's position and velocity (other ranks their own and their
 * ghosts'), and the frame's counters summed over ranks. */
int cs_sim_advance_frame(cs_sim *sim, cs_frame_stats *stats);

/* After cs_sim_advance_frame returned CS_ERR_UNSTABLE: the stage that first
 * saw it, the speed seen (infinity for NaN) and the bound it passed (see
 * sim/runaway.c for what the bound allows); false when none was seen. */
bool cs_sim_runaway(const cs_sim *sim, const char **stage, double *speed, double *limit);

/* After cs_sim_advance_frame returned CS_ERR_SCRIPT: a sentence naming
 * the time, the zone (its size, where it is) and the scripted sets (cloth
 * and script indices) that no collision-free state could follow. */
bool cs_sim_script_conflict(const cs_sim *sim, char *buf, size_t len);

/* Rank 0's value, on every rank (a collective): how the ranks agree to go
 * on or stop after rank 0 has written a frame. */
int cs_sim_agree(cs_sim *sim, int value);

/* MPI for a command (Section 7). Initialises MPI when a launcher (mpirun,
 * srun) started the process, or when CLOTHSIM_MPI=1; a plain run stays one
 * rank without it (no singleton start-up cost) and runs the same code.
 * Returns whether MPI is initialised. */
bool cs_parallel_init(int *argc, char ***argv);
void cs_parallel_finalize(void);
/* This process's rank in MPI_COMM_WORLD; 0 without MPI. */
int cs_parallel_rank(void);
/* OpenMP threads per rank for what follows (call after cs_parallel_init):
 * n > 0 asks for n; 0 takes OMP_NUM_THREADS when set, else one thread per
 * core this process may use (its CPU affinity) shared among the ranks
 * started on this machine, at least one. Returns the count now in force. */
int cs_parallel_set_threads(int n);
/* The OpenMP threads each rank uses. */
int cs_parallel_threads(void);

/* Advances by exactly one time step of the integrator (for tests). */
int cs_sim_step(cs_sim *sim, double dt);

/* Intersecting pairs of non-adjacent triangles over all cloths now, by the
 * independent verifier (cs_count_intersections). */
long cs_sim_count_intersections(const cs_sim *sim);

double cs_sim_time(const cs_sim *sim);
double cs_sim_dt(const cs_sim *sim);          /* step used by advance_frame */
/* Stability limits at the rest state: the one the automatic step uses
 * (def.step_limit), the damped scheme's (the larger of its Gershgorin test
 * and the undamped limit), and the undamped 2 / omega_max by Lanczos and by
 * Gershgorin. */
double cs_sim_stable_dt(const cs_sim *sim);
double cs_sim_damped_dt(const cs_sim *sim);
/* the limit the automatic step uses: def.step_limit, auto resolved */
cs_step_limit cs_sim_step_limit(const cs_sim *sim);
/* what decided step_limit auto's choice, a phrase (NULL when the
 * definition named the limit itself) */
const char *cs_sim_step_limit_why(const cs_sim *sim);
/* at the damped limit, the longest step in the first frame in which a
 * scripted vertex moves its script reach (a quarter of the repulsion
 * thickness; never below the undamped step), and that reach in metres;
 * INFINITY when no script moves then */
double cs_sim_script_step_cap(const cs_sim *sim, double *reach);
/* How far the scripted particle farthest from its script's pose now (on
 * the script's own clock) is from it, m, and which particle (-1: none held):
 * a state given from outside (run --start-from) must put them there. */
double cs_sim_script_offset(const cs_sim *sim, int *vertex);
double cs_sim_undamped_dt(const cs_sim *sim);
double cs_sim_gershgorin_dt(const cs_sim *sim);
int cs_sim_particle_count(const cs_sim *sim);
int cs_sim_spring_count(const cs_sim *sim); /* edge and bending springs */
const double *cs_sim_positions(const cs_sim *sim);
const double *cs_sim_velocities(const cs_sim *sim);
const double *cs_sim_masses(const cs_sim *sim);
int cs_sim_cloth_count(const cs_sim *sim);
/* Particles of cloth c are [offset, offset + mesh->nv); triangle indices in
 * mesh->tri are local to the cloth. */
int cs_sim_cloth_offset(const cs_sim *sim, int c);
const cs_trimesh *cs_sim_cloth_mesh(const cs_sim *sim, int c);
const char *cs_sim_cloth_name(const cs_sim *sim, int c);

const cs_plan *cs_sim_plan(const cs_sim *sim);
/* CS_STAGE_COUNT entries. With several ranks, after cs_sim_advance_frame
 * and on rank 0 only: seconds are the slowest rank's, the communication
 * seconds the largest and bytes and messages the sum over ranks. */
const cs_stage_timing *cs_sim_stage_timing(const cs_sim *sim);
const cs_comm_stats *cs_sim_stage_comm(const cs_sim *sim);
/* This rank and the number of ranks; per rank (cs_sim_ranks entries, on
 * rank 0 after a frame) the communication totals of every stage. */
int cs_sim_rank(const cs_sim *sim);
int cs_sim_ranks(const cs_sim *sim);
const cs_comm_stats *cs_sim_rank_comm(const cs_sim *sim);
/* Bytes the simulation allocated for a stage's own data (0 if absent). */
size_t cs_sim_stage_bytes(const cs_sim *sim, cs_stage stage);

/* How deep the cloth's surface is inside a body now (its true surface, not
 * the collision offset): the largest -phi over free vertices and the
 * centroids and edge midpoints of triangles with a free vertex, 0 when none
 * is inside (or body collisions are off), -1 without memory to look. */
double cs_sim_body_penetration(const cs_sim *sim);

/* ---------------------------------------------------------- tessellation */

/* A triangle mesh of an analytic body at time t, in world coordinates, for
 * drawing: `detail` segments around spheres and cylinders (at least 3); a
 * plane becomes a square of half-size plane_extent about its frame origin.
 * Triangles wind counter-clockwise seen from outside (outward normals);
 * vertices are shared only across smooth parts, so box edges and cylinder
 * caps stay sharp under smooth shading. NULL for a body given by phi_fn,
 * an invalid size, or no memory. Free with cs_trimesh_destroy. */
cs_trimesh *cs_body_def_tessellate(const cs_body_def *b, double t, double plane_extent,
                                   int detail);

/* ----------------------------------------------------- self-intersection */

/* The verifier (sim/verify.c), independent of the collision code: counts
 * the unordered pairs of triangles that share no vertex index and intersect
 * as closed sets. Touching counts, so does coplanar overlap; a degenerate
 * triangle counts as the segment or point it is. Exact for every finite
 * input (filtered floating point, expansion arithmetic, GMP). Returns the
 * count, or CS_ERR_INVALID (an index out of range, a non-finite coordinate
 * of a used vertex, a negative size) or CS_ERR_NOMEM. */
long cs_count_intersections(int nv, const double *x, int nt, const int *tri);

/* The same, also writing the first min(count, maxpairs) intersecting pairs
 * in increasing order, pair k as triangles pairs[2k] < pairs[2k + 1]. */
long cs_find_intersections(int nv, const double *x, int nt, const int *tri, int maxpairs,
                           int *pairs);

/* ------------------------------------------- state for resuming (checkpoint.c) */

/* Everything the end of a frame leaves for the next frames to read, as
 * named arrays of doubles the caller stores and gives back: a simulation
 * created from the same definition and given them continues bit for bit as
 * the one that exported them (at the same rank count). Whatever a step
 * recomputes before reading (forces, contacts, pairs, trees, scratch) is
 * not state; what it reads from an earlier step is, and is listed here. */
typedef struct cs_state_array {
    const char *name;   /* "time", "positions", "cg/warm_half", ... */
    size_t count;       /* doubles */
    double *data;       /* into the simulation: read to store, write to restore */
} cs_state_array;

enum { CS_STATE_MAX_ARRAYS = 10 };

/* The arrays (at most CS_STATE_MAX_ARRAYS) in *arrays; returns how many.
 * The list and the sizes are the same on every rank and for every
 * simulation of the same definition. */
int cs_sim_state_arrays(cs_sim *sim, cs_state_array *arrays);

/* A collective, after cs_sim_advance_frame: rank 0's arrays then hold every
 * particle's values (other ranks keep theirs). Counts as no stage's
 * communication. */
void cs_sim_state_gather(cs_sim *sim);

/* A collective, after rank 0 wrote stored values into its arrays: every
 * rank takes rank 0's. Returns CS_OK or CS_ERR_NOMEM (on every rank). */
int cs_sim_state_scatter(cs_sim *sim);

#ifdef __cplusplus
}
#endif
#endif
