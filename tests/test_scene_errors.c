/* test_scene_errors.c: the YAML scene loader's error messages, one exact
 * message per kind of error ("FILE:LINE: KEY: what was expected (got X)"),
 * and --set overrides: applied, their own errors, and the file's errors
 * keeping their lines. The converted values: test_scene.c. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "import/import.h"
#include "tests/scene_load.h"

#define EPS 1e-12

/* The smallest scene, two lines. */
static const char *grid2 = "cloths:\n  - grid: {resolution: [2, 2]}\n";

/* Appends to the two-line grid2 scene, so extra lines start at line 3. */
static void expect_error_after_grid(const char *more, const char *want)
{
    char text[2048];
    snprintf(text, sizeof text, "%s%s", grid2, more);
    expect_error(text, 0, NULL, want);
}

static void test_error_empty_and_syntax(void **state)
{
    (void)state;
    expect_error("", 0, NULL,
                 "scenes/a.yaml:1: the scene is empty (expected a mapping with at least cloths)");
    expect_error("# nothing but a comment\n", 0, NULL,
                 "scenes/a.yaml:1: the scene is empty (expected a mapping with at least cloths)");
    expect_error("[1, 2]\n", 0, NULL,
                 "scenes/a.yaml:1: expected a mapping of scene keys (got a list)");
    expect_error("name: x\ncloths: [\ntime: {fps: 3}\n", 0, NULL,
                 "scenes/a.yaml:4: YAML syntax error: did not find expected ',' or ']' "
                 "(while parsing a flow sequence at line 2)");
    expect_error_after_grid("time:\n  fps: 3\n fps: 4\n",
                            "scenes/a.yaml:5: YAML syntax error: did not find expected key "
                            "(while parsing a block mapping at line 1)");
    expect_error_after_grid("---\nname: second\n",
                            "scenes/a.yaml:3: only one YAML document is allowed");
}

static void test_error_unknown_key(void **state)
{
    (void)state;
    /* the misspelt key is on line 7; cyaml's backtrace would say line 5 */
    expect_error("name: x\n"
                 "cloths:\n"
                 "  - grid: {resolution: [2, 2]}\n"
                 "time:\n"
                 "  fps: 24\n"
                 "  frames: 3\n"
                 "  fsp: 30\n",
                 0, NULL, "scenes/a.yaml:7: time.fsp: unknown key; did you mean fps?");
    expect_error("cloths:\n"
                 "  - grid: {resolution: [2, 2]}\n"
                 "    material:\n"
                 "      node_mass: 1e-6\n"
                 "      stiffness: 3\n",
                 0, NULL, "scenes/a.yaml:5: cloths[0].material.stiffness: unknown key");
    expect_error_after_grid("gravty: [0, -9.8, 0]\n",
                            "scenes/a.yaml:3: gravty: unknown key; did you mean gravity?");
    /* the nearest known key is named, a transposition counting once */
    expect_error("cloths:\n"
                 "  - grid:\n"
                 "      resolutoin: [2, 2]\n",
                 0, NULL,
                 "scenes/a.yaml:3: cloths[0].grid.resolutoin: unknown key; did you mean "
                 "resolution?");
    expect_error("cloths:\n  - grid: {}\n    pins: [{box: {min: [0, 0, 0], maks: [1, 1, 1]}}]\n",
                 0, NULL,
                 "scenes/a.yaml:3: cloths[0].pins[0].box.maks: unknown key; did you mean max?");
    expect_error_after_grid("time: {fps: 24, fps: 30}\n",
                            "scenes/a.yaml:3: time.fps: duplicate key");
}

static void test_error_wrong_type(void **state)
{
    (void)state;
    expect_error_after_grid("time:\n  frames: 10\n  fps: fast\n",
                            "scenes/a.yaml:5: time.fps: expected a number (got fast)");
    expect_error_after_grid("time:\n  frames: 2.5\n",
                            "scenes/a.yaml:4: time.frames: expected an integer (got 2.5)");
    expect_error_after_grid("time:\n  frames: 3x\n",
                            "scenes/a.yaml:4: time.frames: expected an integer (got 3x)");
    expect_error_after_grid("gravity: [0, nan, 0]\n",
                            "scenes/a.yaml:3: gravity[1]: expected a finite number (got nan)");
    expect_error_after_grid("gravity: [0, -9.8]\n",
                            "scenes/a.yaml:3: gravity: expected a list of 3 numbers "
                            "(got a list of 2)");
    expect_error_after_grid("gravity: 9.8\n",
                            "scenes/a.yaml:3: gravity: expected a list of 3 numbers (got 9.8)");
    expect_error_after_grid("effects:\n  wind: maybe\n",
                            "scenes/a.yaml:4: effects.wind: expected true or false (got maybe)");
    expect_error_after_grid("effects:\n  friction: best\n",
                            "scenes/a.yaml:4: effects.friction: expected one of improved, "
                            "projection (got best)");
    expect_error_after_grid("bodies:\n  - shape: cone\n",
                            "scenes/a.yaml:4: bodies[0].shape: expected one of plane, sphere, "
                            "box, cylinder, mesh (got cone)");
    expect_error_after_grid("output: {format: png}\n",
                            "scenes/a.yaml:3: output.format: expected one of ply, obj, glb "
                            "(got png)");
    expect_error_after_grid("time: 5\n", "scenes/a.yaml:3: time: expected a mapping (got 5)");
    expect_error_after_grid("time:\n  dt: soon\n",
                            "scenes/a.yaml:4: time.dt: expected a number >= 0 or auto (got soon)");
    expect_error("cloths: {grid: {}}\n", 0, NULL,
                 "scenes/a.yaml:1: cloths: expected a list (got a mapping)");
    /* a multi-line value still gives a one-line message */
    expect_error_after_grid("time:\n  fps: \"two\nlines\"\n",
                            "scenes/a.yaml:4: time.fps: expected a number (got two lines)");
}

static void test_error_missing_required(void **state)
{
    (void)state;
    expect_error("name: x\n", 0, NULL, "scenes/a.yaml:1: cloths: required key is missing");
    expect_error("cloths: []\n", 0, NULL,
                 "scenes/a.yaml:1: cloths: expected at least 1 entry (got 0)");
    expect_error_after_grid("camera:\n  target: [0, 0, 0]\n  fov: 30\n",
                            "scenes/a.yaml:3: camera.position: required key is missing");
    expect_error_after_grid("bodies:\n  - name: ball\n    radius: 1\n",
                            "scenes/a.yaml:4: bodies[0].shape: required key is missing");
    expect_error_after_grid("bodies:\n  - shape: sphere\n",
                            "scenes/a.yaml:4: bodies[0].radius: is required for a sphere");
    expect_error("cloths:\n  - name: x\n", 0, NULL,
                 "scenes/a.yaml:2: cloths[0]: expected exactly one of grid or mesh (got neither)");
}

static void test_error_out_of_range(void **state)
{
    (void)state;
    expect_error("cloths:\n"
                 "  - grid: {resolution: [2, 2]}\n"
                 "    material:\n"
                 "      node_mass: -1\n",
                 0, NULL, "scenes/a.yaml:4: cloths[0].material.node_mass: must be > 0 (got -1)");
    expect_error_after_grid("time: {fps: 0}\n", "scenes/a.yaml:3: time.fps: must be > 0 (got 0)");
    expect_error_after_grid("time:\n  dt_safety: 1.5\n",
                            "scenes/a.yaml:4: time.dt_safety: must be in (0, 1] (got 1.5)");
    expect_error_after_grid("time:\n  collision_steps: 0\n",
                            "scenes/a.yaml:4: time.collision_steps: must be >= 1 (got 0)");
    expect_error_after_grid("wind: {drag: -2}\n",
                            "scenes/a.yaml:3: wind.drag: must be >= 0 (got -2)");
    expect_error_after_grid("camera: {position: [0, 0, 1], target: [0, 0, 0], fov: 180}\n",
                            "scenes/a.yaml:3: camera.fov: must be in (0, 180) (got 180)");
    expect_error_after_grid("camera: {position: [0, 0, 1], target: [0, 0, 0],\n"
                            "         motion: {velocity: [1, 0, 0], keys: [{time: 0}]}}\n",
                            "scenes/a.yaml:4: camera.motion: expected either "
                            "velocity/angular_velocity or keys (got both)");
    expect_error_after_grid("camera: {position: [0, 0, 1], target: [0, 0, 0],\n"
                            "         motion: {keys: [{time: 1}, {time: 1}]}}\n",
                            "scenes/a.yaml:4: camera.motion.keys[1].time: must be greater than "
                            "the previous key's time 1 (got 1)");
    expect_error_after_grid("wind: {drag: 1, gust: -0.1}\n",
                            "scenes/a.yaml:3: wind.gust: must be >= 0 (got -0.1)");
    expect_error_after_grid("wind: {drag: 1, gust_length: 0}\n",
                            "scenes/a.yaml:3: wind.gust_length: must be > 0 (got 0)");
    expect_error("cloths:\n  - grid: {size: [1, 0]}\n", 0, NULL,
                 "scenes/a.yaml:2: cloths[0].grid.size[1]: must be > 0 (got 0)");
    expect_error("cloths:\n  - grid: {resolution: [0, 2]}\n", 0, NULL,
                 "scenes/a.yaml:2: cloths[0].grid.resolution[0]: must be >= 1 (got 0)");
    expect_error("cloths:\n  - grid: {}\n    color: [0.5, 1.5, 0]\n", 0, NULL,
                 "scenes/a.yaml:3: cloths[0].color[1]: must be in [0, 1] (got 1.5)");
    expect_error_after_grid("bodies:\n  - shape: box\n    size: [1, 1, -1]\n",
                            "scenes/a.yaml:5: bodies[0].size[2]: must be > 0 (got -1)");
    expect_error_after_grid("bodies:\n  - shape: plane\n    radius: 2\n",
                            "scenes/a.yaml:5: bodies[0].radius: is not used by a plane "
                            "(remove it)");
    expect_error_after_grid("bodies:\n"
                            "  - shape: plane\n"
                            "    normal: [0, 1, 0]\n"
                            "    rotation: [0, 0, 0]\n",
                            "scenes/a.yaml:5: bodies[0].normal: expected either normal or "
                            "rotation (got both)");
}

static void test_error_geometry_and_selection(void **state)
{
    (void)state;
    expect_error("cloths:\n"
                 "  - mesh:\n"
                 "      vertices: [[0, 0, 0], [1, 0, 0], [0, 0, 1]]\n"
                 "      triangles: [[0, 1, 3]]\n",
                 0, NULL,
                 "scenes/a.yaml:4: cloths[0].mesh.triangles[0][2]: must be a vertex index in "
                 "[0, 2] (got 3)");
    expect_error("cloths:\n"
                 "  - mesh:\n"
                 "      vertices: [[0, 0, 0], [1, 0, 0], [0, 0, 1]]\n"
                 "      triangles: [[0, 1, 1]]\n",
                 0, NULL,
                 "scenes/a.yaml:4: cloths[0].mesh.triangles[0]: must name three distinct "
                 "vertices (got [0, 1, 1])");
    expect_error_after_grid("    pins:\n      - box: {min: [5, 5, 5], max: [6, 6, 6]}\n",
                            "scenes/a.yaml:4: cloths[0].pins[0].box: selects no vertex");
    expect_error_after_grid("    pins:\n      - vertices: [1, 9]\n",
                            "scenes/a.yaml:4: cloths[0].pins[0].vertices[1]: must be a vertex "
                            "index in [0, 8] (got 9)");
    expect_error_after_grid("    pins:\n      - {vertices: [1], grid_points: [[0, 0]]}\n",
                            "scenes/a.yaml:4: cloths[0].pins[0]: expected exactly one of "
                            "vertices, box or grid_points (got 2)");
    expect_error_after_grid("    pins:\n"
                            "      - vertices: [0, 1]\n"
                            "    scripts:\n"
                            "      - select: {vertices: [2]}\n"
                            "      - select: {vertices: [1]}\n",
                            "scenes/a.yaml:7: cloths[0].scripts[1].select: must not select a "
                            "pinned vertex (got vertex 1, pinned by cloths[0].pins[0])");
    expect_error_after_grid("    scripts:\n"
                            "      - select: {vertices: [2, 3]}\n"
                            "      - select: {vertices: [3]}\n",
                            "scenes/a.yaml:5: cloths[0].scripts[1].select: must not select a "
                            "vertex of another script (got vertex 3, also in "
                            "cloths[0].scripts[0])");
    expect_error("cloths:\n"
                 "  - mesh: {vertices: [[0, 0, 0]]}\n"
                 "    pins: [{grid_points: [[0, 0]]}]\n",
                 0, NULL,
                 "scenes/a.yaml:3: cloths[0].pins[0].grid_points: only a grid cloth has grid "
                 "points (this cloth is a mesh)");
    expect_error_after_grid("bodies:\n"
                            "  - shape: plane\n"
                            "    motion:\n"
                            "      keys:\n"
                            "        - {time: 1}\n"
                            "        - {time: 0.5}\n",
                            "scenes/a.yaml:8: bodies[0].motion.keys[1].time: must be greater "
                            "than the previous key's time 1 (got 0.5)");
    expect_error_after_grid("bodies:\n"
                            "  - shape: plane\n"
                            "    motion: {velocity: [1, 0, 0], keys: [{time: 0}]}\n",
                            "scenes/a.yaml:5: bodies[0].motion: expected either "
                            "velocity/angular_velocity or keys (got both)");
}

/* ---------------------------------------------------------- overrides */

static const char *base_scene = "name: base\n"
                                "time:\n"
                                "  frames: 5\n"
                                "cloths:\n"
                                "  - grid: {resolution: [2, 2]}\n"
                                "    material: {node_mass: 2e-6}\n"
                                "bodies:\n"
                                "  - shape: plane\n";

static void test_overrides_applied(void **state)
{
    (void)state;
    const char *ov[] = {
        "time.frames=10",
        "gravity=[0, 0, -1]",
        "cloths.0.material.node_mass=3e-6",
        "cloths[0].grid.resolution=[3, 1]",
        "wind.drag=2",
        "camera.position=[0, 0, 5]",
        "camera.target=[0, 0, 0]",
        "bodies.0={shape: sphere, radius: 0.5}",
        "name=renamed scene",
    };
    cs_scene *s = load_ok(base_scene, 9, ov);
    assert_int_equal(s->frames, 10);
    assert_vec(s->def.gravity, 0, 0, -1);
    assert_true(fabs(s->def.cloths[0].material.node_mass - 3e-6) < EPS);
    assert_int_equal(s->def.cloths[0].mesh->nv, 4 * 2);
    assert_true(s->def.wind_enabled);            /* the wind block was created */
    assert_true(s->def.wind.drag == 2);
    assert_true(s->camera.given);
    assert_vec(s->camera.position, 0, 0, 5);
    assert_int_equal(s->def.bodies[0].shape, CS_BODY_SPHERE);
    assert_true(s->def.bodies[0].radius == 0.5);
    assert_string_equal(s->name, "renamed scene");
    cs_scene_destroy(s);
}

static void expect_override_error(const char *ov, const char *want)
{
    const char *list[] = {"time.frames=7", ov};
    expect_error(base_scene, 2, list, want);
}

static void test_override_errors(void **state)
{
    (void)state;
    expect_override_error("gravity=[0, 0",
                          "--set gravity=[0, 0: the value is not valid YAML: did not find "
                          "expected ',' or ']'");
    expect_override_error("time.fsp=3", "--set time.fsp=3: time.fsp: unknown key; did you mean fps?");
    expect_override_error("render.size=3", "--set render.size=3: render: unknown key");
    expect_override_error("cloths.2.name=x",
                          "--set cloths.2.name=x: index 2 is past the end of cloths (1 entry)");
    expect_override_error("cloths.first.name=x",
                          "--set cloths.first.name=x: cloths is a list: 'first' is not an index");
    expect_override_error("time.frames.max=3",
                          "--set time.frames.max=3: time.frames is a single value, it has no "
                          "keys or entries");
    expect_override_error("time.frames", "--set time.frames: expected PATH=VALUE");
    expect_override_error("time..frames=3",
                          "--set time..frames=3: expected a key path like "
                          "cloths.0.material.node_mass before '='");
    expect_override_error("time.fps=fast",
                          "--set time.fps=fast: time.fps: expected a number (got fast)");
    expect_override_error("gravity=[1, 2]",
                          "--set gravity=[1, 2]: gravity: expected a list of 3 numbers (got a "
                          "list of 2)");
    /* range errors found after loading name the override, not a line */
    expect_override_error("cloths.0.material.node_mass=-1",
                          "--set cloths.0.material.node_mass=-1: cloths[0].material.node_mass: "
                          "must be > 0 (got -1)");
    expect_override_error("camera.position=[0, 0, 1]",
                          "--set camera.position=[0, 0, 1]: camera.target: required key is "
                          "missing");
    /* the error is in a block the first override wrote, though the second
     * override's path is closer to it */
    const char *two[] = {"cloths.0.material={node_mass: -1}", "cloths.0.material.density=0.1"};
    expect_error(base_scene, 2, two,
                 "--set cloths.0.material={node_mass: -1}: cloths[0].material.node_mass: must "
                 "be > 0 (got -1)");
    /* the override changed the shape; the missing radius is its doing */
    expect_override_error("bodies.0.shape=sphere",
                          "--set bodies.0.shape=sphere: bodies[0].radius: is required for a "
                          "sphere");
}

/* An override goes into the parsed scene through its key's row: an entry
 * of a vector, a mapping given whole, and the same messages as the file's
 * own keys get; the resolved scene holds it. */
static void test_overrides_through_rows(void **state)
{
    (void)state;
    const char *text = "name: rows\n"
                       "gravity: [0, -9.8, 0]\n"
                       "cloths:\n"
                       "  - grid: {resolution: [2, 2]}\n"
                       "bodies:\n"
                       "  - shape: plane\n";
    const char *ov[] = {"gravity.1=-3", "self_collision={stiffness: 12}",
                        "bodies.0.friction_keys=[{time: 0, friction: 0.7}]"};
    cs_scene *s = load_ok(text, 3, ov);
    assert_vec(s->def.gravity, 0, -3, 0);
    assert_true(s->def.self.stiffness == 12);
    assert_int_equal(s->def.bodies[0].nfriction_keys, 1);
    assert_true(s->def.bodies[0].friction_keys[0].friction == 0.7);
    assert_non_null(strstr(s->resolved, "gravity: [0, -3, 0]"));
    assert_non_null(strstr(s->resolved, "  stiffness: 12\n"));
    assert_null(strstr(s->resolved_setup, "frames:"));
    cs_scene_destroy(s);
    expect_override_error("self_collision.scheme=sometimes",
                          "--set self_collision.scheme=sometimes: self_collision.scheme: expected "
                          "one of fixed, rewind (got sometimes)");
    expect_override_error("effects.bodies=maybe",
                          "--set effects.bodies=maybe: effects.bodies: expected true or false "
                          "(got maybe)");
    expect_override_error("camera={position: [0, 0, 1], target: [0, 0, 0], fvo: 3}",
                          "--set camera={position: [0, 0, 1], target: [0, 0, 0], fvo: 3}: "
                          "camera.fvo: unknown key; did you mean fov?");
    expect_override_error("bodies.0.friction_keys=[{time: 0}]",
                          "--set bodies.0.friction_keys=[{time: 0}]: "
                          "bodies[0].friction_keys[0].friction: required key is missing");
    expect_override_error("time.dt=fast",
                          "--set time.dt=fast: time.dt: expected a number >= 0 or auto (got fast)");
    expect_override_error("cloths=[]", "--set cloths=[]: cloths: expected at least 1 entry (got 0)");
}

/* Errors in the file itself keep their file line when overrides are given. */
static void test_override_keeps_file_lines(void **state)
{
    (void)state;
    const char *text = "name: base\n"
                       "cloths:\n"
                       "  - grid: {resolution: [2, 2]}\n"
                       "    material: {node_mass: -3}\n";
    const char *ov[] = {"time.frames=3"};
    expect_error(text, 1, ov,
                 "scenes/a.yaml:4: cloths[0].material.node_mass: must be > 0 (got -3)");
    /* ... and the file is checked before any override is applied */
    expect_error("cloths:\n  - grid: {}\ntime: {fsp: 3}\n", 1, ov,
                 "scenes/a.yaml:3: time.fsp: unknown key; did you mean fps?");
    /* an override may repair a range error of the file */
    const char *fix[] = {"cloths.0.material.node_mass=3e-6"};
    cs_scene *s = load_ok(text, 1, fix);
    assert_true(fabs(s->def.cloths[0].material.node_mass - 3e-6) < EPS);
    cs_scene_destroy(s);
}


static void test_friction_keys_errors(void **state)
{
    (void)state;
    expect_error_after_grid("bodies:\n"
                            "  - shape: plane\n"
                            "    friction_keys:\n"
                            "      - {time: 0, friction: 0.8}\n"
                            "      - {time: 1, friction: -0.1}\n",
                            "scenes/a.yaml:7: bodies[0].friction_keys[1].friction: must be >= 0 "
                            "(got -0.1)");
    expect_error_after_grid("bodies:\n"
                            "  - shape: plane\n"
                            "    friction_keys:\n"
                            "      - {time: 1, friction: 0.8}\n"
                            "      - {time: 0.5, friction: 0.1}\n",
                            "scenes/a.yaml:7: bodies[0].friction_keys[1].time: must be greater "
                            "than the previous key's time 1 (got 0.5)");
    expect_error_after_grid("bodies:\n"
                            "  - shape: plane\n"
                            "    friction_keys:\n"
                            "      - {time: 1, friction: 0.8}\n"
                            "      - {time: 1, friction: 0.1}\n",
                            "scenes/a.yaml:7: bodies[0].friction_keys[1].time: must be greater "
                            "than the previous key's time 1 (got 1)");
    expect_error_after_grid("bodies:\n"
                            "  - shape: plane\n"
                            "    friction: 0.3\n"
                            "    friction_keys: [{time: 0, friction: 0.8}]\n",
                            "scenes/a.yaml:6: bodies[0].friction_keys: expected either friction "
                            "or friction_keys (got both)");
    expect_error_after_grid("bodies:\n"
                            "  - shape: plane\n"
                            "    friction_keys: [{time: 0}]\n",
                            "scenes/a.yaml:5: bodies[0].friction_keys[0].friction: required key "
                            "is missing");
    char many[1024];
    int w = snprintf(many, sizeof many, "bodies:\n  - shape: plane\n    friction_keys:\n");
    for (int k = 0; k < CS_BODY_MAX_FRICTION_KEYS + 1; k++)
        w += snprintf(many + w, sizeof many - (size_t)w, "      - {time: %d, friction: 0.5}\n", k);
    expect_error_after_grid(many, "scenes/a.yaml:5: bodies[0].friction_keys: must have at most 16 "
                                  "keys (got 17)");
    /* the override names itself */
    const char *ov[] = {"bodies.0.friction_keys=[{time: 0, friction: -1}]"};
    char text[512];
    snprintf(text, sizeof text, "%s%s", grid2, "bodies:\n  - shape: plane\n");
    expect_error(text, 1, ov,
                 "--set bodies.0.friction_keys=[{time: 0, friction: -1}]: "
                 "bodies[0].friction_keys[0].friction: must be >= 0 (got -1)");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_error_empty_and_syntax),
        cmocka_unit_test(test_error_unknown_key),
        cmocka_unit_test(test_error_wrong_type),
        cmocka_unit_test(test_error_missing_required),
        cmocka_unit_test(test_error_out_of_range),
        cmocka_unit_test(test_error_geometry_and_selection),
        cmocka_unit_test(test_overrides_applied),
        cmocka_unit_test(test_override_errors),
        cmocka_unit_test(test_overrides_through_rows),
        cmocka_unit_test(test_override_keeps_file_lines),
        cmocka_unit_test(test_friction_keys_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
