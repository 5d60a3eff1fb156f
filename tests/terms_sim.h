/* terms_sim.h: the term tests' simulation (test_terms.c,
 * test_terms_wind.c, test_terms_selfcol.c): created with the step asked for
 * checked to be the step taken, and advanced a frame at a time. Include
 * after cmocka.h. */
#ifndef CS_TESTS_TERMS_SIM_H
#define CS_TESTS_TERMS_SIM_H

#include <math.h>

#include "sim/sim.h"

static inline cs_sim *create(const cs_sim_def *def)
{
    char err[256] = "";
    cs_sim *sim = cs_sim_create(def, err, sizeof err);
    if (!sim)
        fail_msg("cs_sim_create: %s", err);
    /* the step asked for is the step taken: expectations below use it */
    if (def->dt > 0 && !(fabs(cs_sim_dt(sim) / def->dt - 1) < 1e-12))
        fail_msg("asked for dt = %g, the simulation steps %g", def->dt, cs_sim_dt(sim));
    return sim;
}

static inline void advance(cs_sim *sim)
{
    assert_int_equal(cs_sim_advance_frame(sim, NULL), CS_OK);
}

/* A definition with no gravity and tight solves, one cloth, no bodies:
 * each test switches on the term it checks. */
static inline cs_sim_def bare_def(const cs_cloth_def *cloth, double dt, double fps)
{
    cs_sim_def def = cs_default_sim_def();
    def.gravity[0] = def.gravity[1] = def.gravity[2] = 0;
    def.ncloths = 1;
    def.cloths = cloth;
    def.dt = dt;
    def.fps = fps;
    def.cg_tolerance = 1e-13;
    return def;
}

#endif
