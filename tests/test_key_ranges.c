/* A value is validated against one definition: the range of each
 * scene key lives in import/scene_keys.def, and the loader refuses a value
 * outside it with the file and line. The core checks the same values again
 * for programs that fill cs_sim_def themselves (sim knows no scene files);
 * this test walks the key table and holds the core to each key's range, so
 * the two cannot drift apart: for every key converted straight into a
 * field the core reads, a definition with the value at each bound is
 * accepted where the bound is inclusive and refused where it is exclusive,
 * and one just outside each bound is refused. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "import/import.h"
#include "import/scene_schema.h"
#include "sim/sim.h"
#include "tests/mesh_of.h"

/* A small valid definition with every section the core reads in use: one
 * cloth (two triangles), a sphere body, self-collision and wind. */
typedef struct fixture {
    cs_sim_def def;
    cs_cloth_def cloth;
    cs_body_def body;
    cs_trimesh *mesh;
} fixture;

static void fixture_init(fixture *f)
{
    static const double x[] = {0, 0, 0, 1, 0, 0, 1, 0, 1, 0, 0, 1};
    static const int tri[] = {0, 1, 2, 0, 2, 3};
    f->mesh = mesh_of(4, x, 2, tri);
    f->def = cs_default_sim_def();
    memset(&f->cloth, 0, sizeof f->cloth);
    f->cloth.mesh = f->mesh;
    f->cloth.material = cs_default_cloth_material();
    f->body = cs_default_body_def();
    f->body.shape = CS_BODY_SPHERE;
    f->body.motion.position[1] = -1;
    f->def.cloths = &f->cloth;
    f->def.ncloths = 1;
    f->def.bodies = &f->body;
    f->def.nbodies = 1;
    f->def.self_collision = true;
    f->def.self = cs_default_self_collision_def();
    f->def.wind.drag = 0.1;
    f->def.plan_only = true; /* validation and the plan only */
}

/* Where the key's value lives in the fixture, or NULL when the core does
 * not read it (frames, output, camera, grid sizes: the loader's alone). */
static void *field_of(fixture *f, const cs_scene_key *k)
{
    if (k->section == CS_SEC_time && k->target >= 0) {
        long off = k->target - (long)offsetof(cs_scene, def);
        if (off < 0 || off >= (long)sizeof(cs_sim_def))
            return NULL;
        return (char *)&f->def + off;
    }
    if (k->section == CS_SEC_time && k == CS_SKEY(time, dt))
        return &f->def.dt;
    if (k->target < 0)
        return NULL;
    if (k->section == CS_SEC_effects)
        return (char *)&f->def + k->target;
    if (k->section == CS_SEC_self)
        return (char *)&f->def.self + k->target;
    if (k->section == CS_SEC_wind)
        return (char *)&f->def.wind + k->target;
    if (k->section == CS_SEC_material)
        return (char *)&f->cloth.material + k->target;
    if (k->section == CS_SEC_body)
        return (char *)&f->body + k->target;
    return NULL;
}

/* Sets the field to v, asks the core, restores the field. */
static bool core_accepts(fixture *f, const cs_scene_key *k, void *field, double v)
{
    double saved_num = 0;
    int saved_int = 0;
    if (k->type == CS_KT_INT) {
        memcpy(&saved_int, field, sizeof saved_int);
        int iv = (int)v;
        memcpy(field, &iv, sizeof iv);
    } else {
        memcpy(&saved_num, field, sizeof saved_num);
        memcpy(field, &v, sizeof v);
    }
    char err[256] = "";
    cs_sim *sim = cs_sim_create(&f->def, err, sizeof err);
    cs_sim_destroy(sim);
    if (k->type == CS_KT_INT)
        memcpy(field, &saved_int, sizeof saved_int);
    else
        memcpy(field, &saved_num, sizeof saved_num);
    return sim != NULL;
}

static double outside(const cs_scene_key *k, double bound, double direction)
{
    return k->type == CS_KT_INT ? bound + direction : nextafter(bound, direction * INFINITY);
}

static void core_holds_every_key_range(void **state)
{
    (void)state;
    fixture f;
    fixture_init(&f);
    char err[256] = "";
    cs_sim *sim = cs_sim_create(&f.def, err, sizeof err);
    assert_non_null(sim); /* the fixture itself is valid */
    cs_sim_destroy(sim);

    int checked = 0, failures = 0;
    for (int i = 0; i < CS_KEY_COUNT; i++) {
        const cs_scene_key *k = cs_scene_keys + i;
        if (k->type != CS_KT_NUM && k->type != CS_KT_INT && k->type != CS_KT_DT)
            continue;
        void *field = field_of(&f, k);
        if (!field)
            continue;
        const cs_key_range *r = &k->range;
        const char *sec = cs_scene_sections[k->section].heading;
        struct {
            int kind;
            double bound, direction;
        } bounds[2] = {{r->lo_kind, r->lo, -1}, {r->hi_kind, r->hi, +1}};
        for (int b = 0; b < 2; b++) {
            if (bounds[b].kind == CS_BOUND_NONE)
                continue;
            checked++;
            double at = bounds[b].bound, out = outside(k, at, bounds[b].direction);
            bool at_ok = bounds[b].kind == CS_BOUND_GE;
            if (core_accepts(&f, k, field, at) != at_ok) {
                print_error("%s.%s = %g: the table %s it, the core does not\n", sec, k->key, at,
                            at_ok ? "accepts" : "refuses");
                failures++;
            }
            if (core_accepts(&f, k, field, out)) {
                print_error("%s.%s = %.17g: outside the table's range, the core accepts it\n",
                            sec, k->key, out);
                failures++;
            }
        }
    }
    /* every bounded number the core reads: time (fps, dt, dt_safety,
     * collision_steps, cg_*), self_collision, wind drag, the material and
     * the body's radius, friction and offset */
    assert_true(checked >= 20);
    assert_int_equal(failures, 0);
    cs_trimesh_destroy(f.mesh);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(core_holds_every_key_range),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
