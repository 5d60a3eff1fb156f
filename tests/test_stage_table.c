/* Unit tests of the stage table: it names every stage once, a plan is its
 * rows in the table's order, and the stages that run are exactly the
 * plan's: every planned stage runs as often as its place in the loop says
 * (each time step, each outer step, each frame), every other one never
 * runs and owns no memory. Only the public interface is used, and the
 * plan read off a definition (cs_plan_from_def, sim/stages.h). */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "sim/sim.h"
#include "sim/stages.h"
#include "grid_cloth.h"

static void test_table_names_every_stage_once(void **state)
{
    (void)state;
    int seen[CS_STAGE_COUNT] = {0};
    for (int i = 0; i < CS_STAGE_COUNT; i++) {
        cs_stage st = cs_stage_in_order(i);
        assert_true(st >= 0 && st < CS_STAGE_COUNT);
        seen[st]++;
        assert_true(strlen(cs_stage_name(st)) > 0);
        assert_true(strlen(cs_stage_description(st)) > 0);
        assert_true(strlen(cs_stage_condition(st)) > 0);
        assert_true(strlen(cs_stage_when(st)) > 0);
        for (int j = 0; j < i; j++)
            assert_string_not_equal(cs_stage_name(st), cs_stage_name(cs_stage_in_order(j)));
    }
    for (int s = 0; s < CS_STAGE_COUNT; s++)
        assert_int_equal(seen[s], 1);
    assert_int_equal(cs_stage_in_order(CS_STAGE_COUNT), CS_STAGE_COUNT);
    assert_int_equal(cs_stage_in_order(-1), CS_STAGE_COUNT);
}

/* Where stage st sits in the table. */
static int table_row(cs_stage st)
{
    for (int i = 0; i < CS_STAGE_COUNT; i++)
        if (cs_stage_in_order(i) == st)
            return i;
    return -1;
}

/* How often a planned stage must have run after `frames` frames of
 * `steps` time steps in outer steps of `outer` (no rewinds). */
static long expected_calls(cs_stage st, int frames, long steps, long outer)
{
    switch (st) {
    case CS_STAGE_REPULSION_PAIRS:
    case CS_STAGE_COLLISIONS: return outer;
    case CS_STAGE_FRAME_END:
    case CS_STAGE_VERIFY: return frames;
    default: return steps;
    }
}

/* Runs two frames of def and holds the stages run to the plan. */
static void check_plan_is_what_runs(const cs_sim_def *def, int expected_stages)
{
    cs_sim *sim = cs_sim_create(def, NULL, 0);
    assert_non_null(sim);
    const cs_plan *plan = cs_sim_plan(sim);
    cs_plan from_def = cs_plan_from_def(def);
    assert_int_equal(plan->nstages, expected_stages);
    assert_int_equal(from_def.nstages, plan->nstages);
    for (int i = 0; i < plan->nstages; i++) {
        assert_int_equal(from_def.stages[i], plan->stages[i]);
        if (i > 0) /* in the table's order */
            assert_true(table_row(plan->stages[i - 1]) < table_row(plan->stages[i]));
    }
    const int frames = 2;
    long steps = 0, outer = 0;
    for (int f = 0; f < frames; f++) {
        cs_frame_stats stats;
        assert_int_equal(cs_sim_advance_frame(sim, &stats), CS_OK);
        steps += stats.steps;
        outer += (stats.steps + def->collision_steps - 1) / def->collision_steps;
        if (cs_plan_has(plan, CS_STAGE_VERIFY))
            assert_int_equal(stats.intersections, 0);
        else
            assert_int_equal(stats.intersections, -1);
    }
    const cs_stage_timing *t = cs_sim_stage_timing(sim);
    for (int s = 0; s < CS_STAGE_COUNT; s++) {
        cs_stage st = (cs_stage)s;
        if (cs_plan_has(plan, st)) {
            assert_int_equal(t[st].calls, expected_calls(st, frames, steps, outer));
        } else {
            assert_int_equal(t[st].calls, 0);
            assert_true(t[st].seconds == 0);
            assert_int_equal(cs_sim_stage_bytes(sim, st), 0);
        }
    }
    cs_sim_destroy(sim);
}

static void test_plan_is_what_runs(void **state)
{
    (void)state;
    cs_cloth_def cloth;
    cs_trimesh *mesh;
    cs_sim_def def = grid_def(&cloth, &mesh, 6, 7);
    def.collision_steps = 4;
    cs_body_def ground = cs_default_body_def();
    ground.motion.position[1] = 0.9;
    def.nbodies = 1;
    def.bodies = &ground;

    /* self-collision off: the time step's five stages and the frame's end */
    check_plan_is_what_runs(&def, 6);

    /* on, with the verifier, wind and a pin: every stage */
    int pinned = 0;
    cs_vertex_script pin = {1, &pinned, cs_motion_static(), 0};
    cloth.nscripts = 1;
    cloth.scripts = &pin;
    def.wind_enabled = true;
    def.wind.drag = 0.5;
    def.wind.velocity[0] = 1;
    def.self_collision = true;
    def.self.verify = true;
    check_plan_is_what_runs(&def, CS_STAGE_COUNT);

    /* on, without bodies: their two stages left out, the rest as planned */
    def.bodies_enabled = false;
    check_plan_is_what_runs(&def, CS_STAGE_COUNT - 2);
    cs_trimesh_destroy(mesh);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_table_names_every_stage_once),
        cmocka_unit_test(test_plan_is_what_runs),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
