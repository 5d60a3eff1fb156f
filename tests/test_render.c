/* Tests of the renderer (render/render.h) with both engines:
 *   - a sphere's silhouette lands where the camera model says: the hit mask
 *     of pixel-centre rays against the analytic projection;
 *   - images are deterministic: the same bytes twice, and for 1 and 2
 *     threads (random numbers are seeded per pixel and sample);
 *   - small scenes match reference images in tests/reference/ within a
 *     tolerance (on failure the image and a difference image are written
 *     into the test's working directory, and the message says where;
 *     CS_UPDATE_REFERENCES=1 rewrites the references instead);
 *   - bad input (sizes, meshes, cameras) is refused with a message;
 *   - PNG files, shrinking, contact sheets, camera helpers.
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "render/render.h"
#include "sim/sim.h"

#define ERRLEN 512

/* ------------------------------------------------------------- the scene */

typedef struct test_scene {
    cs_trimesh *cloth, *ball, *ground;
    cs_render_mesh meshes[3];
    int n;
    cs_render_camera camera;
} test_scene;

/* A sheet with radial folds draped over a ball on the ground. */
static void scene_make(test_scene *s)
{
    memset(s, 0, sizeof *s);
    double size[2] = {1.4, 1.4}, q[4] = {1, 0, 0, 0}, c[3] = {0, 0, 0};
    int res[2] = {24, 24};
    s->cloth = cs_trimesh_create_grid(size, res, q, c);
    assert_non_null(s->cloth);
    for (int v = 0; v < s->cloth->nv; v++) {
        double *p = s->cloth->x + 3 * v, r = sqrt(p[0] * p[0] + p[2] * p[2]);
        p[1] = 0.78 - 0.6 * r * r + 0.04 * r * sin(9 * atan2(p[2], p[0]));
    }
    cs_body_def ball = cs_default_body_def(), ground = cs_default_body_def();
    ball.shape = CS_BODY_SPHERE;
    ball.radius = 0.35;
    ball.motion.position[1] = 0.35;
    ground.shape = CS_BODY_PLANE;
    s->ball = cs_body_def_tessellate(&ball, 0, 0, 32);
    s->ground = cs_body_def_tessellate(&ground, 0, 6, 0);
    assert_non_null(s->ball);
    assert_non_null(s->ground);
    s->meshes[0] = (cs_render_mesh){.name = "cloth", .nv = s->cloth->nv, .nt = s->cloth->nt,
                                    .x = s->cloth->x, .tri = s->cloth->tri,
                                    .color = {0.75, 0.22, 0.18}, .two_sided = true};
    s->meshes[1] = (cs_render_mesh){.name = "ball", .nv = s->ball->nv, .nt = s->ball->nt,
                                    .x = s->ball->x, .tri = s->ball->tri,
                                    .color = {0.8, 0.8, 0.8}, .closed = true};
    s->meshes[2] = (cs_render_mesh){.name = "ground", .nv = s->ground->nv,
                                    .nt = s->ground->nt, .x = s->ground->x,
                                    .tri = s->ground->tri, .color = {0.5, 0.5, 0.5},
                                    .backdrop = true};
    s->n = 3;
    s->camera = (cs_render_camera){{1.8, 1.5, 2.2}, {0, 0.35, 0}, {0, 1, 0}, 40};
}

static void scene_free(test_scene *s)
{
    cs_trimesh_destroy(s->cloth);
    cs_trimesh_destroy(s->ball);
    cs_trimesh_destroy(s->ground);
}

static cs_render_settings settings_for(cs_render_engine engine, int w, int h, int samples)
{
    cs_render_settings st = cs_render_default_settings();
    st.engine = engine;
    st.width = w;
    st.height = h;
    st.samples = samples;
    return st;
}

/* Renders or fails the test. */
static cs_image *render(const cs_render_settings *st, int n, const cs_render_mesh *m,
                        const cs_render_camera *cam, cs_render_stats *stats)
{
    char err[ERRLEN] = "";
    cs_renderer *r = cs_renderer_create(st, err, sizeof err);
    if (!r)
        fail_msg("cs_renderer_create: %s", err);
    cs_image *img = cs_image_create(st->width, st->height);
    assert_non_null(img);
    int rc = cs_renderer_draw(r, n, m, cam, img, stats, err, sizeof err);
    if (rc != CS_OK)
        fail_msg("cs_renderer_draw (%s): %s", cs_render_engine_name(st->engine), err);
    cs_renderer_destroy(r);
    return img;
}

/* --------------------------------------------------------- the silhouette */

static void sub3(const double a[3], const double b[3], double o[3])
{
    for (int i = 0; i < 3; i++)
        o[i] = a[i] - b[i];
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static void unit3(double a[3])
{
    double n = sqrt(dot3(a, a));
    for (int i = 0; i < 3; i++)
        a[i] /= n;
}

/* The sphere alone in the sky, one sample at each pixel centre: every pixel
 * whose centre ray passes the centre closer than r (less a band for the
 * tessellation and rounding) must be hit, every one farther than r (plus
 * the band) missed. The camera model is written out here independently of
 * render/camera.c. */
static void check_silhouette(cs_render_engine engine)
{
    const double centre[3] = {0.1, 0.5, -0.2}, r = 0.4;
    const int slices = 64, W = 160, H = 120;
    cs_body_def ball = cs_default_body_def();
    ball.shape = CS_BODY_SPHERE;
    ball.radius = r;
    memcpy(ball.motion.position, centre, sizeof centre);
    cs_trimesh *m = cs_body_def_tessellate(&ball, 0, 0, slices);
    assert_non_null(m);
    cs_render_mesh mesh = {.name = "ball", .nv = m->nv, .nt = m->nt, .x = m->x, .tri = m->tri,
                           .color = {0.8, 0.8, 0.8}, .closed = true};
    cs_render_camera cam = {{1.5, 1.2, 2.5}, {0, 0.4, 0}, {0, 1, 0}, 35};
    cs_render_settings st = settings_for(engine, W, H, 1);
    cs_image *img = render(&st, 1, &mesh, &cam, NULL);

    double f[3], right[3], up[3];
    sub3(cam.target, cam.position, f);
    unit3(f);
    cross3(f, cam.up, right);
    unit3(right);
    cross3(right, f, up);
    double th = tan(0.5 * cam.fov_degrees * M_PI / 180), aspect = (double)W / H;
    double oc[3];
    sub3(centre, cam.position, oc);
    /* Facets lie inside the sphere by at most r (1 - cos(pi / slices)) over
     * a latitude-longitude grid (twice that near the poles' fans); allow
     * that plus float rounding, in distance from the centre. */
    double band = 2.5 * r * (1 - cos(M_PI / slices)) + 1e-4;
    int inside = 0, hits = 0, wrong = 0, in_band = 0;
    double cx_a = 0, cy_a = 0, cx_m = 0, cy_m = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double sx = (2 * (x + 0.5) / W - 1) * th * aspect, sy = (1 - 2 * (y + 0.5) / H) * th;
            double d[3];
            for (int i = 0; i < 3; i++)
                d[i] = f[i] + sx * right[i] + sy * up[i];
            unit3(d);
            double along = dot3(oc, d), dist = sqrt(fmax(dot3(oc, oc) - along * along, 0));
            bool hit = img->coverage[y * W + x] >= 128;
            hits += hit;
            if (dist < r) {
                inside++;
                cx_a += x;
                cy_a += y;
            }
            if (hit) {
                cx_m += x;
                cy_m += y;
            }
            if (fabs(dist - r) <= band) {
                in_band++;
                continue;
            }
            if (hit != (dist < r)) {
                if (wrong < 5)
                    print_message("%s: pixel (%d, %d) %s, analytic distance %.5f vs r %.3f\n",
                                  cs_render_engine_name(engine), x, y, hit ? "hit" : "missed",
                                  dist, r);
                wrong++;
            }
        }
    assert_true(inside > 500);   /* the sphere is well inside the frame */
    assert_int_equal(wrong, 0);
    assert_true(in_band < inside / 10);
    /* Same place: mask centroids within a fifth of a pixel. */
    assert_true(fabs(cx_a / inside - cx_m / hits) < 0.2);
    assert_true(fabs(cy_a / inside - cy_m / hits) < 0.2);

    /* cs_render_camera_project agrees with the model written out above. */
    double px[2];
    assert_true(cs_render_camera_project(&cam, W, H, centre, px));
    double z = dot3(oc, f);
    assert_true(fabs(px[0] - 0.5 * (dot3(oc, right) / z / (th * aspect) + 1) * W) < 1e-9);
    assert_true(fabs(px[1] - 0.5 * (1 - dot3(oc, up) / z / th) * H) < 1e-9);
    cs_image_destroy(img);
    cs_trimesh_destroy(m);
}

static void test_silhouette_embree(void **state)
{
    (void)state;
    check_silhouette(CS_RENDER_EMBREE);
}

static void test_silhouette_preview(void **state)
{
    (void)state;
    check_silhouette(CS_RENDER_PREVIEW);
}

/* ------------------------------------------------------------ determinism */

static void test_determinism(void **state)
{
    (void)state;
    test_scene s;
    scene_make(&s);
    cs_render_settings st = settings_for(CS_RENDER_EMBREE, 96, 72, 4);
    st.threads = 2;
    cs_image *a = render(&st, s.n, s.meshes, &s.camera, NULL);
    cs_image *b = render(&st, s.n, s.meshes, &s.camera, NULL);
    st.threads = 1;
    cs_image *c = render(&st, s.n, s.meshes, &s.camera, NULL);
    size_t bytes = 3 * 96 * 72;
    assert_memory_equal(a->rgb, b->rgb, bytes);
    assert_memory_equal(a->rgb, c->rgb, bytes);
    assert_memory_equal(a->coverage, c->coverage, 96 * 72);

    cs_render_settings pv = settings_for(CS_RENDER_PREVIEW, 96, 72, 4);
    cs_image *d = render(&pv, s.n, s.meshes, &s.camera, NULL);
    cs_image *e = render(&pv, s.n, s.meshes, &s.camera, NULL);
    assert_memory_equal(d->rgb, e->rgb, bytes);
    cs_image_destroy(a);
    cs_image_destroy(b);
    cs_image_destroy(c);
    cs_image_destroy(d);
    cs_image_destroy(e);
    scene_free(&s);
}

/* ------------------------------------------------------ reference images */

/* Compares with tests/reference/NAME.png: the mean absolute difference per
 * channel and the share of pixels differing by more than `large` must stay
 * small (the path tracer's noise moves when floating point rounds another
 * way on another CPU; the picture does not). */
static void compare_reference(const cs_image *img, const char *name, double mean_tol,
                              int large, double share_tol)
{
    char ref_path[1024], err[ERRLEN];
    snprintf(ref_path, sizeof ref_path, "%s/tests/reference/%s.png", CS_SOURCE_DIR, name);
    const char *update = getenv("CS_UPDATE_REFERENCES");
    if (update && *update && strcmp(update, "0") != 0) {
        assert_int_equal(cs_image_write_png(img, ref_path, err, sizeof err), CS_OK);
        print_message("wrote reference %s\n", ref_path);
        return;
    }
    cs_image *ref = cs_image_read_png(ref_path, err, sizeof err);
    if (!ref)
        fail_msg("%s (make it with CS_UPDATE_REFERENCES=1)", err);
    assert_int_equal(ref->width, img->width);
    assert_int_equal(ref->height, img->height);
    size_t n = (size_t)img->width * (size_t)img->height;
    cs_image *diff = cs_image_create(img->width, img->height);
    assert_non_null(diff);
    double sum = 0;
    size_t big = 0;
    for (size_t i = 0; i < n; i++) {
        int worst = 0;
        for (int c = 0; c < 3; c++) {
            int d = abs((int)img->rgb[3 * i + c] - (int)ref->rgb[3 * i + c]);
            sum += d;
            worst = d > worst ? d : worst;
            diff->rgb[3 * i + c] = (unsigned char)(d * 4 > 255 ? 255 : d * 4);
        }
        big += worst > large;
    }
    double mean = sum / (3.0 * n), share = (double)big / n;
    print_message("%s: mean difference %.3f (tolerance %.2f), %.3f%% of pixels differ by more "
                  "than %d (tolerance %.2f%%)\n",
                  name, mean, mean_tol, 100 * share, large, 100 * share_tol);
    if (mean > mean_tol || share > share_tol) {
        char actual[1024], dpath[1024], cwd[512];
        if (!getcwd(cwd, sizeof cwd))
            snprintf(cwd, sizeof cwd, ".");
        snprintf(actual, sizeof actual, "%s/%s_actual.png", cwd, name);
        snprintf(dpath, sizeof dpath, "%s/%s_diff.png", cwd, name);
        cs_image_write_png(img, actual, err, sizeof err);
        cs_image_write_png(diff, dpath, err, sizeof err);
        fail_msg("%s differs from %s: the image is %s, the difference (x4) %s", name, ref_path,
                 actual, dpath);
    }
    cs_image_destroy(diff);
    cs_image_destroy(ref);
}

static void test_reference_embree(void **state)
{
    (void)state;
    test_scene s;
    scene_make(&s);
    cs_render_settings st = settings_for(CS_RENDER_EMBREE, 160, 120, 16);
    cs_render_stats stats;
    cs_image *img = render(&st, s.n, s.meshes, &s.camera, &stats);
    assert_true(stats.rays >= 160 * 120 * 16);
    assert_true(stats.covered > 160 * 120 / 2);
    compare_reference(img, "embree_160x120", 3.0, 64, 0.01);
    cs_image_destroy(img);
    scene_free(&s);
}

static void test_reference_preview(void **state)
{
    (void)state;
    test_scene s;
    scene_make(&s);
    cs_render_settings st = settings_for(CS_RENDER_PREVIEW, 160, 120, 4);
    cs_image *img = render(&st, s.n, s.meshes, &s.camera, NULL);
    compare_reference(img, "preview_160x120", 1.5, 64, 0.005);
    cs_image_destroy(img);
    st.wireframe = true;
    st.flat = true;
    img = render(&st, s.n, s.meshes, &s.camera, NULL);
    compare_reference(img, "preview_wire_160x120", 2.0, 64, 0.01);
    cs_image_destroy(img);
    scene_free(&s);
}

/* The two engines agree on framing and, roughly, on colour: compare the
 * coverage masks and the mean colour of the cloth. */
static void test_engines_agree(void **state)
{
    (void)state;
    test_scene s;
    scene_make(&s);
    cs_render_settings st = settings_for(CS_RENDER_EMBREE, 80, 60, 1);
    cs_image *a = render(&st, 2, s.meshes, &s.camera, NULL);   /* no ground */
    st.engine = CS_RENDER_PREVIEW;
    cs_image *b = render(&st, 2, s.meshes, &s.camera, NULL);
    int differ = 0, covered = 0;
    for (int i = 0; i < 80 * 60; i++) {
        covered += a->coverage[i] > 127;
        differ += (a->coverage[i] > 127) != (b->coverage[i] > 127);
    }
    assert_true(covered > 300);
    assert_true(differ <= covered / 50);   /* edge pixels only */
    cs_image_destroy(a);
    cs_image_destroy(b);
    scene_free(&s);
}

/* -------------------------------------------------------------- bad input */

static void expect_bad(cs_render_engine engine, int n, const cs_render_mesh *m,
                       const cs_render_camera *cam, const char *needle)
{
    char err[ERRLEN] = "";
    cs_render_settings st = settings_for(engine, 32, 24, 1);
    cs_renderer *r = cs_renderer_create(&st, err, sizeof err);
    assert_non_null(r);
    cs_image *img = cs_image_create(32, 24);
    int rc = cs_renderer_draw(r, n, m, cam, img, NULL, err, sizeof err);
    if (rc != CS_ERR_BAD_INPUT || !strstr(err, needle))
        fail_msg("expected bad input mentioning '%s', got %d: %s", needle, rc, err);
    cs_image_destroy(img);
    cs_renderer_destroy(r);
}

static void test_bad_input(void **state)
{
    (void)state;
    char err[ERRLEN];
    cs_render_settings st = settings_for(CS_RENDER_EMBREE, 0, 10, 1);
    assert_null(cs_renderer_create(&st, err, sizeof err));
    assert_non_null(strstr(err, "size"));
    st = settings_for(CS_RENDER_PREVIEW, 100000, 10, 1);
    assert_int_equal(cs_render_settings_check(&st, err, sizeof err), CS_ERR_BAD_INPUT);
    assert_null(cs_renderer_create(&st, err, sizeof err));
    st = settings_for(CS_RENDER_EMBREE, 10, 10, 0);
    assert_int_equal(cs_render_settings_check(&st, err, sizeof err), CS_ERR_BAD_INPUT);
    assert_null(cs_image_create(0, 5));
    assert_int_equal(cs_render_png("x.png", 0, NULL, NULL, NULL, err, sizeof err),
                     CS_ERR_FAILED);

    test_scene s;
    scene_make(&s);
    for (int e = 0; e < 2; e++) {
        cs_render_engine engine = e ? CS_RENDER_PREVIEW : CS_RENDER_EMBREE;
        expect_bad(engine, 0, s.meshes, &s.camera, "no meshes");
        cs_render_mesh m = s.meshes[0];
        m.nt = 0;
        expect_bad(engine, 1, &m, &s.camera, "no triangles");
        m = s.meshes[0];
        int tri[3] = {0, 1, m.nv};
        m.tri = tri;
        m.nt = 1;
        expect_bad(engine, 1, &m, &s.camera, "out of range");
        m = s.meshes[0];
        m.color[1] = 1.5;
        expect_bad(engine, 1, &m, &s.camera, "colour");
        double x[9] = {0, 0, 0, 1, 0, 0, 0, NAN, 1};
        int t1[3] = {0, 1, 2};
        cs_render_mesh bad = {.nv = 3, .nt = 1, .x = x, .tri = t1};
        expect_bad(engine, 1, &bad, &s.camera, "non-finite");

        cs_render_camera cam = s.camera;
        memcpy(cam.target, cam.position, sizeof cam.target);
        expect_bad(engine, s.n, s.meshes, &cam, "target is at its position");
        cam = s.camera;
        cam.fov_degrees = 180;
        expect_bad(engine, s.n, s.meshes, &cam, "fov");
        cam = s.camera;
        for (int i = 0; i < 3; i++)
            cam.up[i] = cam.target[i] - cam.position[i];
        expect_bad(engine, s.n, s.meshes, &cam, "along its view");
        /* Inside the ball, looking out. */
        cam = (cs_render_camera){{0.05, 0.3, 0.02}, {1, 0.3, 0}, {0, 1, 0}, 40};
        expect_bad(engine, s.n, s.meshes, &cam, "inside mesh 'ball'");
        /* Looking up into the empty sky. */
        cam = (cs_render_camera){{0, 3, 0}, {0, 5, 0}, {1, 0, 0}, 40};
        expect_bad(engine, s.n, s.meshes, &cam, "sees nothing");
    }
    scene_free(&s);
}

/* ---------------------------------------------------- files and helpers */

static void test_png_and_helpers(void **state)
{
    (void)state;
    char err[ERRLEN];
    cs_image *img = cs_image_create(37, 21);
    assert_non_null(img);
    for (int i = 0; i < 3 * 37 * 21; i++)
        img->rgb[i] = (unsigned char)(i * 7);
    assert_int_equal(cs_image_write_png(img, "test_render_io.png", err, sizeof err),
                     CS_OK);
    cs_image *back = cs_image_read_png("test_render_io.png", err, sizeof err);
    assert_non_null(back);
    assert_int_equal(back->width, 37);
    assert_int_equal(back->height, 21);
    assert_memory_equal(back->rgb, img->rgb, 3 * 37 * 21);
    assert_null(cs_image_read_png("no/such/file.png", err, sizeof err));
    assert_non_null(strstr(err, "No such file"));
    assert_int_equal(cs_image_write_png(img, "no/such/dir/x.png", err, sizeof err),
                     CS_ERR_FAILED);

    cs_image *small = cs_image_shrink(img, 10);
    assert_non_null(small);
    assert_int_equal(small->width, 10);
    assert_int_equal(small->height, 6);
    const cs_image *three[3] = {img, img, img};
    const char *labels[3] = {"a", "b", "c"};
    assert_int_equal(cs_render_contact_sheet("test_render_sheet.png", 3, three, labels, 2, 20,
                                             err, sizeof err),
                     CS_OK);
    cs_image *sheet = cs_image_read_png("test_render_sheet.png", err, sizeof err);
    assert_non_null(sheet);
    assert_int_equal(sheet->width, 2 * (20 + 6) + 6);
    cs_image_destroy(sheet);
    cs_image_destroy(small);
    cs_image_destroy(back);
    cs_image_destroy(img);
    remove("test_render_io.png");
    remove("test_render_sheet.png");

    /* Camera: ray and projection invert each other; a full orbit returns. */
    cs_render_camera cam = {{1, 2, 3}, {0, 0.5, 0}, {0, 1, 0}, 50};
    for (int k = 0; k < 10; k++) {
        double p[3] = {0.3 * k - 1.2, 0.1 * k, -0.2 * k}, px[2], d[3], q[3];
        assert_true(cs_render_camera_project(&cam, 200, 100, p, px));
        cs_render_camera_ray(&cam, 200, 100, px[0], px[1], d);
        sub3(p, cam.position, q);
        unit3(q);
        assert_true(dot3(q, d) > 1 - 1e-12);
    }
    double behind[3] = {2, 3, 5}, px[2];
    assert_false(cs_render_camera_project(&cam, 200, 100, behind, px));
    double centre[3] = {0, 0, 0}, axis[3] = {0, 1, 0};
    cs_render_camera o = cs_render_camera_orbit(&cam, centre, axis, 2 * M_PI);
    for (int i = 0; i < 3; i++)
        assert_true(fabs(o.position[i] - cam.position[i]) < 1e-12);
    o = cs_render_camera_orbit(&cam, centre, axis, M_PI);
    assert_true(fabs(o.position[0] + 1) < 1e-12 && fabs(o.position[2] + 3) < 1e-12);

    /* Automatic framing sees the whole box. */
    double lo[3] = {-1, 0, -0.5}, hi[3] = {1, 0.4, 0.5};
    cs_render_camera f = cs_render_camera_frame(lo, hi, 4.0 / 3.0);
    assert_int_equal(cs_render_camera_check(&f, err, sizeof err), CS_OK);
    for (int k = 0; k < 8; k++) {
        double p[3] = {k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]};
        assert_true(cs_render_camera_project(&f, 160, 120, p, px));
        assert_true(px[0] >= 0 && px[0] <= 160 && px[1] >= 0 && px[1] <= 120);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_silhouette_embree),
        cmocka_unit_test(test_silhouette_preview),
        cmocka_unit_test(test_determinism),
        cmocka_unit_test(test_reference_embree),
        cmocka_unit_test(test_reference_preview),
        cmocka_unit_test(test_engines_agree),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_png_and_helpers),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
