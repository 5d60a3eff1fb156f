/* Unit tests of the simulation core's time step as a whole: the plan of
 * stages, the automatic time step and the steps it refuses, runaway
 * detection, wind drag against its terminal velocity, bodies and scripts
 * moving particles, and two cloths against each alone. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim/internal.h"
#include "sim/vec3.h"
#include "grid_cloth.h"

static void test_plan_omits_absent_stages(void **state)
{
    (void)state;
    cs_cloth_def cloth;
    cs_trimesh *mesh;
    cs_sim_def def = grid_def(&cloth, &mesh, 4, 19);
    def.wind.drag = 1;              /* wind given but switched off */
    def.wind_enabled = false;
    cs_sim *sim = cs_sim_create(&def, NULL, 0);
    assert_non_null(sim);
    const cs_plan *plan = cs_sim_plan(sim);
    assert_false(cs_plan_has(plan, CS_STAGE_BODY_COLLISION));
    assert_false(cs_plan_has(plan, CS_STAGE_BODY_FRICTION));
    assert_false(cs_plan_has(plan, CS_STAGE_WIND));
    assert_false(cs_plan_has(plan, CS_STAGE_SCRIPTED_VERTICES));
    assert_true(cs_plan_has(plan, CS_STAGE_VELOCITY_HALF));
    assert_int_equal(cs_sim_advance_frame(sim, NULL), CS_OK);
    const cs_stage_timing *t = cs_sim_stage_timing(sim);
    cs_stage absent[] = {CS_STAGE_BODY_COLLISION, CS_STAGE_BODY_FRICTION, CS_STAGE_WIND,
                         CS_STAGE_SCRIPTED_VERTICES, CS_STAGE_REPULSION_PAIRS,
                         CS_STAGE_SELF_REPULSION, CS_STAGE_SELF_FRICTION, CS_STAGE_COLLISIONS,
                         CS_STAGE_VERIFY};
    for (size_t k = 0; k < sizeof absent / sizeof *absent; k++) {
        assert_int_equal(t[absent[k]].calls, 0);
        assert_true(t[absent[k]].seconds == 0);
        assert_int_equal(cs_sim_stage_bytes(sim, absent[k]), 0);
    }
    assert_null(sim->contact_normal);
    assert_null(sim->wind_normal);
    assert_null(sim->selfcol); /* self-collision off: no hierarchy, no pairs */
    assert_true(t[CS_STAGE_VELOCITY_HALF].calls > 0);
    cs_sim_destroy(sim);

    /* with a body, wind and a pin, all three appear and run */
    cs_body_def body = cs_default_body_def();
    int pinned = 0;
    cs_vertex_script pin = {1, &pinned, cs_motion_static(), 0};
    cloth.nscripts = 1;
    cloth.scripts = &pin;
    def.nbodies = 1;
    def.bodies = &body;
    def.wind_enabled = true;
    sim = cs_sim_create(&def, NULL, 0);
    assert_non_null(sim);
    plan = cs_sim_plan(sim);
    assert_true(cs_plan_has(plan, CS_STAGE_BODY_COLLISION) && cs_plan_has(plan, CS_STAGE_WIND) &&
                cs_plan_has(plan, CS_STAGE_SCRIPTED_VERTICES));
    assert_int_equal(cs_sim_advance_frame(sim, NULL), CS_OK);
    t = cs_sim_stage_timing(sim);
    assert_true(t[CS_STAGE_BODY_COLLISION].calls > 0 && t[CS_STAGE_WIND].calls > 0);
    assert_true(cs_sim_stage_bytes(sim, CS_STAGE_BODY_COLLISION) > 0);
    /* the pinned vertex has not moved */
    for (int d = 0; d < 3; d++)
        assert_true(cs_sim_positions(sim)[d] == mesh->x[d]);
    cs_sim_destroy(sim);

    /* self-collision on: its four stages run and own their memory */
    def.self_collision = true;
    sim = cs_sim_create(&def, NULL, 0);
    assert_non_null(sim);
    cs_stage self_stages[] = {CS_STAGE_REPULSION_PAIRS, CS_STAGE_SELF_REPULSION,
                              CS_STAGE_SELF_FRICTION, CS_STAGE_COLLISIONS};
    assert_int_equal(cs_sim_advance_frame(sim, NULL), CS_OK);
    t = cs_sim_stage_timing(sim);
    for (size_t k = 0; k < 4; k++) {
        assert_true(cs_plan_has(cs_sim_plan(sim), self_stages[k]));
        assert_true(t[self_stages[k]].calls > 0);
    }
    assert_true(cs_sim_stage_bytes(sim, CS_STAGE_COLLISIONS) > 0);
    assert_false(cs_plan_has(cs_sim_plan(sim), CS_STAGE_VERIFY)); /* not asked for */
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}

/* A hanging cloth pinned at two corners stays stable at several resolutions
 * with the automatic step; the step shrinks as the springs get shorter. */
static void test_automatic_dt_is_stable_across_resolutions(void **state)
{
    (void)state;
    double last_dt = INFINITY;
    int resolutions[] = {4, 8, 16};
    for (int r = 0; r < 3; r++) {
        double size[2] = {1, 1}, q[4] = {1, 0, 0, 0}, c[3] = {0, 0, 0};
        int res[2] = {resolutions[r], resolutions[r]};
        cs_trimesh *mesh = cs_trimesh_create_grid(size, res, q, c);
        int corners[2] = {0, resolutions[r]};
        cs_vertex_script pin = {2, corners, cs_motion_static(), 0};
        cs_cloth_def cloth = {.name = "c", .mesh = mesh, .material = cs_default_cloth_material(),
                              .nscripts = 1, .scripts = &pin};
        cs_sim_def def = cs_default_sim_def();
        def.ncloths = 1;
        def.cloths = &cloth;
        def.fps = 60;
        cs_sim *sim = cs_sim_create(&def, NULL, 0);
        assert_non_null(sim);
        assert_true(cs_sim_dt(sim) < last_dt);
        assert_true(cs_sim_dt(sim) <= 0.5 * cs_sim_stable_dt(sim) * (1 + 1e-12));
        last_dt = cs_sim_dt(sim);
        cs_frame_stats st;
        for (int f = 0; f < 30; f++) {
            assert_int_equal(cs_sim_advance_frame(sim, &st), CS_OK);
            assert_true(st.max_speed < 10);
        }
        /* it fell, and hangs below the pins without flying apart */
        const double *x = cs_sim_positions(sim);
        double lowest = 0;
        for (int i = 0; i < cs_sim_particle_count(sim); i++) {
            assert_true(cs_norm(x + 3 * i) < 2.5);
            lowest = fmin(lowest, x[3 * i + 1]);
        }
        assert_true(lowest < -0.3);
        cs_sim_destroy(sim);
        cs_trimesh_destroy(mesh);
    }
}

/* A hanging cloth like the one above (8 x 8, pinned at two corners): its
 * definition, the cloth's in static storage. */
static cs_sim_def hanging_cloth_def(cs_trimesh **mesh, double stiffness)
{
    double size[2] = {1, 1}, q[4] = {1, 0, 0, 0}, c[3] = {0, 0, 0};
    int res[2] = {8, 8};
    static int corners[2] = {0, 8};
    static cs_vertex_script pin;
    pin = (cs_vertex_script){2, corners, cs_motion_static(), 0};
    *mesh = cs_trimesh_create_grid(size, res, q, c);
    static cs_cloth_def cloth;
    cloth = (cs_cloth_def){.name = "c", .mesh = *mesh, .material = cs_default_cloth_material(),
                           .nscripts = 1, .scripts = &pin};
    if (stiffness > 0)
        cloth.material.edge_stiffness = stiffness;
    cs_sim_def def = cs_default_sim_def();
    def.ncloths = 1;
    def.cloths = &cloth;
    def.fps = 60;
    return def;
}

static cs_sim *hanging_cloth(cs_trimesh **mesh, double dt, double stiffness, char *err,
                             size_t errlen, int *status)
{
    cs_sim_def def = hanging_cloth_def(mesh, stiffness);
    def.dt = dt;
    cs_sim *sim = NULL;
    *status = cs_sim_create_checked(&def, &sim, err, errlen);
    return sim;
}

/* The hanging cloth at the automatic step and its material's stiffness */
static cs_sim *default_hanging_cloth(cs_trimesh **mesh)
{
    char err[512];
    int status;
    cs_sim *sim = hanging_cloth(mesh, 0, 0, err, sizeof err, &status);
    assert_int_equal(status, CS_OK);
    return sim;
}

/* step_limit auto takes the damped limit exactly when it is at least
 * auto_min_gain times the undamped one: gains just under and just over the
 * cloth's own ratio of the two limits give the two choices. */
static void test_auto_takes_damped_above_its_gain(void **state)
{
    (void)state;
    cs_trimesh *mesh;
    cs_sim_def def = hanging_cloth_def(&mesh, 0);
    cs_sim *sim = cs_sim_create(&def, NULL, 0);
    assert_non_null(sim);
    double ratio = cs_sim_damped_dt(sim) / cs_sim_undamped_dt(sim);
    assert_true(ratio > def.auto_min_gain); /* Table 1's material takes damped */
    assert_int_equal(cs_sim_step_limit(sim), CS_STEP_DAMPED);
    cs_sim_destroy(sim);
    for (int above = 0; above <= 1; above++) {
        def.auto_min_gain = ratio * (above ? 1.001 : 0.999);
        sim = cs_sim_create(&def, NULL, 0);
        assert_non_null(sim);
        cs_step_limit want = above ? CS_STEP_UNDAMPED : CS_STEP_DAMPED;
        assert_int_equal(cs_sim_step_limit(sim), want);
        assert_non_null(strstr(cs_sim_step_limit_why(sim), above ? "below" : "at least"));
        double limit = above ? cs_sim_undamped_dt(sim) : cs_sim_damped_dt(sim);
        assert_true(fabs(cs_sim_stable_dt(sim) - limit) <= 1e-12 * limit);
        cs_sim_destroy(sim);
    }
    def.auto_min_gain = 0.5;
    char err[256] = "";
    assert_null(cs_sim_create(&def, err, sizeof err));
    assert_non_null(strstr(err, "auto_min_gain"));
    cs_trimesh_destroy(mesh);
}

/* Steps the scene cannot take are refused at creation with the reason, not
 * run: a step so small that a frame needs more than CS_MAX_STEPS_PER_FRAME
 * of them (it used to overflow an int and become one step per frame), and a
 * stiffness that makes the stability limit that small. A fixed step above
 * the undamped limit is allowed (damping keeps it stable, see below). */
static void test_impossible_steps_are_refused(void **state)
{
    (void)state;
    cs_trimesh *mesh;
    char err[512];
    int status;
    cs_sim *sim = hanging_cloth(&mesh, 0, 0, err, sizeof err, &status);
    assert_int_equal(status, CS_OK);
    double limit = cs_sim_stable_dt(sim);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);

    sim = hanging_cloth(&mesh, 1.01 * limit, 0, err, sizeof err, &status);
    assert_int_equal(status, CS_OK);
    assert_true(cs_sim_dt(sim) == 1.01 * limit || cs_sim_dt(sim) < 1.01 * limit);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);

    sim = hanging_cloth(&mesh, 1e-12, 0, err, sizeof err, &status);
    assert_null(sim);
    assert_int_equal(status, CS_ERR_INVALID);
    assert_non_null(strstr(err, "time.dt is too small"));
    cs_trimesh_destroy(mesh);

    sim = hanging_cloth(&mesh, 0, 1e308, err, sizeof err, &status);
    assert_null(sim);
    assert_int_equal(status, CS_ERR_INVALID);
    assert_non_null(strstr(err, "stiffness and mass"));
    cs_trimesh_destroy(mesh);
}

/* An n x n sheet of 1 m, no gravity, whose corners 0 and n a script
 * moves dx along x from t = 0 to t1, then holds (self-collisions of
 * thickness h when h > 0); *mesh must outlive the sim. */
static cs_sim *dragged_sheet(int n, double dx, double t1, double h, cs_trimesh **mesh)
{
    double size[2] = {1, 1}, q[4] = {1, 0, 0, 0}, c[3] = {0, 0, 0};
    int res[2] = {n, n}, corners[2] = {0, n};
    cs_keyframe keys[2] = {{0, {0, 0, 0}, {1, 0, 0, 0}}, {t1, {dx, 0, 0}, {1, 0, 0, 0}}};
    cs_motion motion = cs_motion_static();
    motion.kind = CS_MOTION_KEYFRAMES;
    motion.nkeys = 2;
    motion.keys = keys;
    cs_vertex_script drag = {2, corners, motion, 0};
    *mesh = cs_trimesh_create_grid(size, res, q, c);
    cs_cloth_def cloth = {.name = "c", .mesh = *mesh, .material = cs_default_cloth_material(),
                          .nscripts = dx != 0 ? 1 : 0, .scripts = &drag};
    cs_sim_def def = cs_default_sim_def();
    def.ncloths = 1;
    def.cloths = &cloth;
    def.gravity[0] = def.gravity[1] = def.gravity[2] = 0;
    def.self_collision = h > 0;
    if (h > 0)
        def.self.thickness = h;
    char err[512];
    cs_sim *sim = NULL;
    assert_int_equal(cs_sim_create_checked(&def, &sim, err, sizeof err), CS_OK);
    return sim;
}

/* The runaway bound follows what drives the cloth: cloth keeps the speed a
 * script gave it after the script stops, and a script step C held back
 * catches up at twice its speed. A twist whose ends stop at their last key
 * (tests/data/scenes/twist_jam.yaml) whipped at 16.8 m/s a step later and
 * was called unstable: the bound had dropped from 10 times the ends' speed
 * to the wave term alone. */
static void test_runaway_bound_keeps_what_scripts_gave(void **state)
{
    (void)state;
    /* the scripted corners move 1 m along x in 0.5 s (2 m/s), then stop */
    cs_trimesh *mesh;
    cs_sim *sim = dragged_sheet(4, 1, 0.5, 0, &mesh);
    /* at t = 0 the script has not moved yet (a motion is still before its
     * first key): the terms without it */
    double still = cs_runaway_limit(sim, 0);
    assert_true(still > 0);
    /* the script's speed is 2 m/s plus nothing turning: 10 x 2 while it
     * moves, and still after its last key */
    assert_true(fabs(cs_runaway_limit(sim, 0.25) - (still + 20)) < 1e-9);
    assert_true(fabs(cs_runaway_limit(sim, 2.0) - (still + 20)) < 1e-9);
    /* held 0.3 s behind: at t = 0.6 its clock reads 0.3, inside the keys,
     * and it catches up at 4 m/s */
    sim->script_lag[0] = 0.3;
    assert_true(fabs(cs_runaway_limit(sim, 0.6) - (still + 40)) < 1e-9);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}

/* The first frame's step of an 8 x 8 sheet dragged at v by two corners
 * (still for v = 0), and its limits and script reach */
static double dragged_sheet_step(double v, double *undamped, double *damped, double *reach)
{
    cs_trimesh *mesh;
    cs_sim *sim = dragged_sheet(8, v, 1.0, 0.004, &mesh);
    assert_int_equal(cs_sim_step_limit(sim), CS_STEP_DAMPED);
    cs_sim_def def = cs_default_sim_def();
    *undamped = def.dt_safety * cs_sim_undamped_dt(sim);
    *damped = def.dt_safety * cs_sim_damped_dt(sim);
    cs_sim_script_step_cap(sim, reach);
    double dt = cs_sim_dt(sim);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
    return dt;
}

/* The frame of 1/24 s in equal steps of at most dt */
static double frame_step(double dt)
{
    double frame = 1.0 / 24;
    return frame / ceil(frame / dt - 1e-9);
}

/* At the damped limit a moving script caps the step so that its vertices
 * move at most a quarter of the repulsion thickness a step: for a
 * translation at v, dt = (h / 4) / v. The cap never goes below the
 * undamped step, and a sheet without scripts keeps the damped limit. */
static void test_moving_script_caps_the_damped_step(void **state)
{
    (void)state;
    double undamped, damped, reach;
    double still = dragged_sheet_step(0, &undamped, &damped, &reach);
    assert_true(damped > 8 * undamped); /* room for a cap between them */
    assert_true(fabs(still - frame_step(damped)) < 1e-12);
    /* a cap halfway (in log) between the two limits */
    double cap = sqrt(undamped * damped), v = 0.001 / cap;
    double capped = dragged_sheet_step(v, &undamped, &damped, &reach);
    assert_true(fabs(reach - 0.001) < 1e-15);
    assert_true(fabs(capped - frame_step(cap)) < 1e-12 * cap);
    assert_true(capped < 0.5 * frame_step(damped));
    /* ten times faster than the undamped step allows: the undamped step */
    double fast = dragged_sheet_step(10 * 0.001 / undamped, &undamped, &damped, &reach);
    assert_true(fabs(fast - frame_step(undamped)) < 1e-12 * undamped);
}

/* Far past the stability limit the explicit elastic forces grow
 * geometrically: 91 times the undamped limit (the one step per frame that
 * time.dt: 1e-12 used to become) must be caught early (the issue saw the
 * drape reach 1.4e6 m/s and exit "ok"), named with the stage that saw it;
 * the same cloth at the automatic step runs 60 frames without a false
 * alarm. (Up to 40 times the limit this damped cloth stays stable.) */
static void test_runaway_is_detected_with_its_stage(void **state)
{
    (void)state;
    cs_trimesh *mesh;
    cs_sim *sim = default_hanging_cloth(&mesh);
    double dt = 91 * cs_sim_undamped_dt(sim);
    int steps = 0, rc = CS_OK;
    while (rc == CS_OK && steps < 200) {
        rc = cs_sim_step(sim, dt);
        steps++;
    }
    assert_int_equal(rc, CS_ERR_UNSTABLE);
    const char *stage = NULL;
    double speed = 0, limit = 0;
    assert_true(cs_sim_runaway(sim, &stage, &speed, &limit));
    assert_true(strcmp(stage, "velocity_half") == 0 || strcmp(stage, "velocity_full") == 0);
    assert_true(speed > limit);
    /* caught early: a limit of hundreds of m/s, not after the state is NaN */
    assert_true(isfinite(speed));
    assert_true(limit < 1000);
    assert_true(steps < 40);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);

    sim = default_hanging_cloth(&mesh);
    cs_frame_stats st;
    for (int f = 0; f < 60; f++) {
        if (cs_sim_advance_frame(sim, &st) != CS_OK) {
            cs_sim_runaway(sim, &stage, &speed, &limit);
            fail_msg("frame %d: %s %g > %g", f, stage, speed, limit);
        }
    }
    assert_false(cs_sim_runaway(sim, NULL, NULL, NULL));
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}


/* B.6's velocity at a particle in body contact carries the contact impulse
 * (the improved friction turns it into friction in B.7), so the check after
 * velocity_full leaves such particles to the check after body_friction; a
 * free particle as fast is caught at once. */
static void test_runaway_waits_for_b7_at_contacts(void **state)
{
    (void)state;
    cs_trimesh *mesh;
    cs_sim *sim = default_hanging_cloth(&mesh);
    int i = sim->n / 2; /* a free particle */
    assert_true(sim->is_free[i]);
    double *v = calloc(3 * (size_t)sim->n, sizeof *v);
    cs_runaway_begin_step(sim, 0.1);
    v[3 * i + 1] = -2 * sim->runaway.limit; /* into the body, past the limit */
    sim->mode[i] = CS_CONTACT;
    cs_runaway_check(sim, v, CS_STAGE_VELOCITY_FULL);
    assert_false(cs_sim_runaway(sim, NULL, NULL, NULL));
    cs_runaway_check(sim, v, CS_STAGE_BODY_FRICTION); /* B.7 did not remove it */
    const char *stage = NULL;
    assert_true(cs_sim_runaway(sim, &stage, NULL, NULL));
    assert_string_equal(stage, "body_friction");
    sim->runaway.stage = -1;
    sim->mode[i] = CS_FREE;
    cs_runaway_check(sim, v, CS_STAGE_VELOCITY_FULL);
    assert_true(cs_sim_runaway(sim, &stage, NULL, NULL));
    assert_string_equal(stage, "velocity_full");
    free(v);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}

/* Linear normal drag (Section 8): a horizontal sheet of areal density rho
 * falling in still air feels -c A (v.n) n per vertex and m = rho A, so every
 * vertex follows v(t) = v_t (1 - exp(-c t / rho)), v_t = rho g / c, exactly. */
static void test_wind_drag_terminal_velocity(void **state)
{
    (void)state;
    double size[2] = {1, 1}, q[4] = {1, 0, 0, 0}, c[3] = {0, 0, 0};
    int res[2] = {6, 6};
    cs_trimesh *mesh = cs_trimesh_create_grid(size, res, q, c);
    cs_cloth_def cloth = {.name = "sheet", .mesh = mesh, .material = cs_default_cloth_material()};
    cloth.material.density = 0.1;
    cs_sim_def def = cs_default_sim_def();
    def.ncloths = 1;
    def.cloths = &cloth;
    def.fps = 100;
    def.wind_enabled = true;
    def.wind.drag = 1.0;
    def.cg_tolerance = 1e-10;
    cs_sim *sim = cs_sim_create(&def, NULL, 0);
    assert_non_null(sim);
    double rho = 0.1, cd = 1.0, vt = rho * 9.8 / cd;
    for (int f = 1; f <= 50; f++) {
        assert_int_equal(cs_sim_advance_frame(sim, NULL), CS_OK);
        double t = cs_sim_time(sim), exact = -vt * (1 - exp(-cd * t / rho));
        for (int i = 0; i < cs_sim_particle_count(sim); i++) {
            const double *v = cs_sim_velocities(sim) + 3 * i;
            assert_true(fabs(v[1] - exact) < 1e-4 * vt);
            assert_true(fabs(v[0]) < 1e-9 && fabs(v[2]) < 1e-9);
        }
    }
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}

/* Friction from a moving body: a particle at rest on a plane sliding along
 * x at 1 m/s is dragged at mu g until it moves with the plane, then rides
 * along (static friction). */
static void test_moving_body_drags_particle(void **state)
{
    (void)state;
    cs_trimesh *mesh = cs_trimesh_create(1, 0);
    cs_cloth_def cloth = {.name = "p", .mesh = mesh, .material = cs_default_cloth_material()};
    cs_body_def belt = cs_default_body_def();
    belt.friction = 0.5;
    belt.motion.kind = CS_MOTION_CONSTANT;
    belt.motion.velocity[0] = 1.0;
    cs_sim_def def = cs_default_sim_def();
    def.ncloths = 1;
    def.cloths = &cloth;
    def.nbodies = 1;
    def.bodies = &belt;
    def.fps = 100;
    def.dt = 1e-3;
    cs_sim *sim = cs_sim_create(&def, NULL, 0);
    assert_non_null(sim);
    double a = 0.5 * 9.8, t_match = 1.0 / a;
    for (int f = 1; f <= 50; f++) {
        assert_int_equal(cs_sim_advance_frame(sim, NULL), CS_OK);
        double t = cs_sim_time(sim);
        double x = t < t_match ? 0.5 * a * t * t : 0.5 * a * t_match * t_match + (t - t_match);
        double v = t < t_match ? a * t : 1.0;
        const double *px = cs_sim_positions(sim), *pv = cs_sim_velocities(sim);
        assert_true(fabs(px[0] - x) < 1e-3 * 1e-1 + 1e-6);
        assert_true(fabs(pv[0] - v) < 1e-9 + (fabs(t - t_match) < 2e-3 ? a * 1e-3 : 0));
        assert_true(fabs(px[1]) < 1e-12); /* stays on the belt */
    }
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}

/* Keyframed vertices land exactly on their path; free ones follow. */
static void test_scripted_vertices_follow_keys(void **state)
{
    (void)state;
    double size[2] = {1, 1}, q[4] = {1, 0, 0, 0}, c[3] = {0, 0, 0};
    int res[2] = {4, 4};
    cs_trimesh *mesh = cs_trimesh_create_grid(size, res, q, c);
    int moved[2] = {0, 4};
    cs_keyframe keys[2] = {{0, {0, 0, -0.5}, {1, 0, 0, 0}}, {1, {0, 2, -0.5}, {1, 0, 0, 0}}};
    cs_vertex_script script = {2, moved, cs_motion_static(), 0};
    script.motion.kind = CS_MOTION_KEYFRAMES;
    script.motion.position[2] = -0.5;
    script.motion.nkeys = 2;
    script.motion.keys = keys;
    cs_cloth_def cloth = {.name = "c", .mesh = mesh, .material = cs_default_cloth_material(),
                          .nscripts = 1, .scripts = &script};
    cloth.material.density = 0.1;
    cs_sim_def def = cs_default_sim_def();
    def.ncloths = 1;
    def.cloths = &cloth;
    def.fps = 10;
    cs_sim *sim = cs_sim_create(&def, NULL, 0);
    assert_non_null(sim);
    for (int f = 1; f <= 10; f++) {
        assert_int_equal(cs_sim_advance_frame(sim, NULL), CS_OK);
        double t = cs_sim_time(sim);
        for (int k = 0; k < 2; k++) {
            const double *x = cs_sim_positions(sim) + 3 * moved[k];
            const double *v = cs_sim_velocities(sim) + 3 * moved[k];
            assert_true(fabs(x[1] - 2 * t) < 1e-12);
            assert_true(fabs(x[0] - mesh->x[3 * moved[k]]) < 1e-12);
            assert_true(fabs(v[1] - 2) < 1e-12);
        }
    }
    /* the cloth was lifted with its pinned edge, and hangs below it */
    const double *x = cs_sim_positions(sim);
    double centre_y = x[3 * 12 + 1];
    assert_true(centre_y > 0.8 && centre_y < 2.0);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}

/* Several cloths in one simulation behave as each would alone: particle
 * indices, springs and masses of the second cloth are offset correctly. */
static void test_two_cloths_match_each_alone(void **state)
{
    (void)state;
    double size_a[2] = {1, 1}, size_b[2] = {0.7, 1.3}, q[4] = {1, 0, 0, 0};
    double ca[3] = {0, 0, 0}, cb[3] = {3, 1, 0};
    int ra[2] = {5, 4}, rb[2] = {3, 6};
    cs_trimesh *ma = cs_trimesh_create_grid(size_a, ra, q, ca);
    cs_trimesh *mb = cs_trimesh_create_grid(size_b, rb, q, cb);
    int pin_a = 0, pin_b = 2;
    cs_vertex_script sa = {1, &pin_a, cs_motion_static(), 0}, sb = {1, &pin_b, cs_motion_static(), 0};
    cs_cloth_def cloths[2] = {
        {.name = "a", .mesh = ma, .material = cs_default_cloth_material(), .nscripts = 1, .scripts = &sa},
        {.name = "b", .mesh = mb, .material = cs_default_cloth_material(), .nscripts = 1, .scripts = &sb},
    };
    cloths[0].material.density = 0.1;
    cloths[1].material.density = 0.2;
    cloths[1].material.edge_stiffness = 20;
    cs_sim_def def = cs_default_sim_def();
    def.cloths = cloths;
    def.cg_tolerance = 1e-13;
    def.fps = 30;
    def.dt = 1e-4;
    def.ncloths = 2;
    cs_sim *both = cs_sim_create(&def, NULL, 0);
    def.ncloths = 1;
    cs_sim *alone_a = cs_sim_create(&def, NULL, 0);
    def.cloths = cloths + 1;
    cs_sim *alone_b = cs_sim_create(&def, NULL, 0);
    assert_non_null(both);
    assert_non_null(alone_a);
    assert_non_null(alone_b);
    assert_int_equal(cs_sim_cloth_offset(both, 1), ma->nv);
    for (int f = 0; f < 6; f++) {
        assert_int_equal(cs_sim_advance_frame(both, NULL), CS_OK);
        assert_int_equal(cs_sim_advance_frame(alone_a, NULL), CS_OK);
        assert_int_equal(cs_sim_advance_frame(alone_b, NULL), CS_OK);
    }
    const double *x = cs_sim_positions(both);
    double moved = 0;
    for (int k = 0; k < 3 * ma->nv; k++)
        assert_true(fabs(x[k] - cs_sim_positions(alone_a)[k]) < 1e-9);
    for (int k = 0; k < 3 * mb->nv; k++) {
        assert_true(fabs(x[3 * ma->nv + k] - cs_sim_positions(alone_b)[k]) < 1e-9);
        moved = fmax(moved, fabs(x[3 * ma->nv + k] - mb->x[k]));
    }
    assert_true(moved > 0.05);
    cs_sim_destroy(both);
    cs_sim_destroy(alone_a);
    cs_sim_destroy(alone_b);
    cs_trimesh_destroy(ma);
    cs_trimesh_destroy(mb);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_plan_omits_absent_stages),
        cmocka_unit_test(test_automatic_dt_is_stable_across_resolutions),
        cmocka_unit_test(test_impossible_steps_are_refused),
        cmocka_unit_test(test_auto_takes_damped_above_its_gain),
        cmocka_unit_test(test_runaway_is_detected_with_its_stage),
        cmocka_unit_test(test_runaway_waits_for_b7_at_contacts),
        cmocka_unit_test(test_runaway_bound_keeps_what_scripts_gave),
        cmocka_unit_test(test_moving_script_caps_the_damped_step),
        cmocka_unit_test(test_wind_drag_terminal_velocity),
        cmocka_unit_test(test_moving_body_drags_particle),
        cmocka_unit_test(test_scripted_vertices_follow_keys),
        cmocka_unit_test(test_two_cloths_match_each_alone),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
