/* render_speed.c: how fast the renderer is, for docs/performance.md (not a timed
 * test). A cloth of about 200,000 triangles, wrinkled over a ball on the
 * ground, is ray traced at 1280x720 with 16 samples per pixel (rays per
 * second, seconds per frame) and drawn by the preview (frames per second).
 * Every figure is the median of 3 runs.
 *
 * usage: bench_render_speed [OUTDIR]   (OUTDIR: also write the images there)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "common/util.h"
#include "render/render.h"
#include "sim/sim.h"

#define RUNS 3

/* CPU seconds of the whole process (all threads): on a machine shared with
 * other work, CPU time / cores estimates the wall time of an idle one. */
static double cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* A square sheet draped over a ball of radius R centred at height c: the
 * middle wraps the ball down to its equator, the rest hangs straight down in
 * folds that deepen towards the ground, then spreads over the ground. */
static cs_trimesh *wrinkled_cloth(int res, double R, double c)
{
    double size[2] = {2.4, 2.4}, q[4] = {1, 0, 0, 0}, centre[3] = {0, 0, 0};
    int r[2] = {res + 1, res};
    cs_trimesh *m = cs_trimesh_create_grid(size, r, q, centre);
    if (!m)
        return NULL;
    double lift = R + 0.004, quarter = 0.5 * M_PI * lift;
    for (int v = 0; v < m->nv; v++) {
        double *p = m->x + 3 * v;
        double s = sqrt(p[0] * p[0] + p[2] * p[2]), th = atan2(p[2], p[0]);
        double radial, y;
        if (s < quarter) {                  /* on the ball */
            double phi = s / lift;
            radial = lift * sin(phi);
            y = c + lift * cos(phi);
        } else {
            double down = s - quarter;      /* length hanging below the equator */
            double fold = 0.05 * (1 - exp(-4 * down)) * (1 + sin(11 * th + 2 * down));
            radial = lift + fold;
            y = c - down;
            if (y < 0.004) {                /* spread on the ground */
                radial += -y + 0.004;
                y = 0.004 + 0.012 * (1 + sin(7 * th + 20 * radial));
            }
        }
        p[0] = radial * cos(th);
        p[1] = y;
        p[2] = radial * sin(th);
    }
    return m;
}

int main(int argc, char **argv)
{
    const char *outdir = argc > 1 ? argv[1] : NULL;
    double R = 0.35, c = 0.35;
    cs_trimesh *cloth = wrinkled_cloth(316, R, c);
    cs_body_def ball = cs_default_body_def(), ground = cs_default_body_def();
    ball.shape = CS_BODY_SPHERE;
    ball.radius = R;
    ball.motion.position[1] = c;
    ground.shape = CS_BODY_PLANE;
    cs_trimesh *ballm = cs_body_def_tessellate(&ball, 0, 0, 64);
    cs_trimesh *groundm = cs_body_def_tessellate(&ground, 0, 12, 0);
    if (!cloth || !ballm || !groundm) {
        fprintf(stderr, "bench_render_speed: out of memory\n");
        return 1;
    }
    cs_render_mesh meshes[3] = {
        {.name = "cloth", .nv = cloth->nv, .nt = cloth->nt, .x = cloth->x, .tri = cloth->tri,
         .color = {0.75, 0.22, 0.18}, .two_sided = true},
        {.name = "ball", .nv = ballm->nv, .nt = ballm->nt, .x = ballm->x, .tri = ballm->tri,
         .color = {0.8, 0.8, 0.8}, .closed = true},
        {.name = "ground", .nv = groundm->nv, .nt = groundm->nt, .x = groundm->x,
         .tri = groundm->tri, .color = {0.5, 0.5, 0.5}, .backdrop = true},
    };
    double lo[3], hi[3];
    cs_render_bounds(3, meshes, lo, hi);
    cs_render_camera cam = cs_render_camera_frame(lo, hi, 1280.0 / 720.0);
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    printf("cloth: %d triangles, %d vertices; %ld cores\n", cloth->nt, cloth->nv, cores);

    char err[512];
    cs_render_settings s = cs_render_default_settings();
    s.width = 1280;
    s.height = 720;
    s.samples = 16;
    cs_image *img = cs_image_create(s.width, s.height);
    cs_renderer *r = cs_renderer_create(&s, err, sizeof err);
    if (!img || !r) {
        fprintf(stderr, "bench_render_speed: %s\n", err);
        return 1;
    }
    double secs[RUNS], rays[RUNS], cpu[RUNS];
    long long nrays = 0;
    for (int k = 0; k < RUNS; k++) {
        cs_render_stats st;
        double c0 = cpu_seconds();
        if (cs_renderer_draw(r, 3, meshes, &cam, img, &st, err, sizeof err) != CS_OK) {
            fprintf(stderr, "bench_render_speed: %s\n", err);
            return 1;
        }
        cpu[k] = cpu_seconds() - c0;
        secs[k] = st.seconds;
        rays[k] = (double)st.rays / st.seconds;
        nrays = st.rays;
        printf("embree run %d: %.3f s (%.3f CPU s), %lld rays, %.2f Mrays/s\n", k + 1,
               st.seconds, cpu[k], st.rays, rays[k] * 1e-6);
    }
    cs_renderer_destroy(r);
    if (outdir) {
        char path[4096];
        snprintf(path, sizeof path, "%s/bench_embree.png", outdir);
        if (cs_image_write_png(img, path, err, sizeof err) != CS_OK)
            fprintf(stderr, "bench_render_speed: %s\n", err);
    }
    double embree_s = median(secs, RUNS), embree_rays = median(rays, RUNS);
    double embree_cpu = median(cpu, RUNS);

    /* Preview: 4x multisampling, and without (the wireframe costs extra). */
    double fps[2][RUNS], fps_cpu[2][RUNS];
    for (int msaa = 0; msaa < 2; msaa++) {
        cs_render_settings p = s;
        p.engine = CS_RENDER_PREVIEW;
        p.samples = msaa ? 4 : 1;
        double t0 = cs_now();
        r = cs_renderer_create(&p, err, sizeof err);
        if (!r) {
            fprintf(stderr, "bench_render_speed: %s\n", err);
            return 1;
        }
        printf("preview (%d sample%s): context and shaders %.3f s\n", p.samples,
               p.samples > 1 ? "s" : "", cs_now() - t0);
        int frames = 10;
        for (int k = 0; k < RUNS; k++) {
            t0 = cs_now();
            double c0 = cpu_seconds();
            for (int f = 0; f < frames; f++)
                if (cs_renderer_draw(r, 3, meshes, &cam, img, NULL, err, sizeof err) !=
                    CS_OK) {
                    fprintf(stderr, "bench_render_speed: %s\n", err);
                    return 1;
                }
            fps[msaa][k] = frames / (cs_now() - t0);
            fps_cpu[msaa][k] = frames / (cpu_seconds() - c0);
            printf("preview run %d: %.2f frames/s (%.2f per CPU second)\n", k + 1, fps[msaa][k],
                   fps_cpu[msaa][k]);
        }
        cs_renderer_destroy(r);
        if (outdir && msaa) {
            char path[4096];
            snprintf(path, sizeof path, "%s/bench_preview.png", outdir);
            if (cs_image_write_png(img, path, err, sizeof err) != CS_OK)
                fprintf(stderr, "bench_render_speed: %s\n", err);
        }
    }

    double load[3] = {0, 0, 0};
    FILE *la = fopen("/proc/loadavg", "r");
    if (la) {
        if (fscanf(la, "%lf %lf %lf", &load[0], &load[1], &load[2]) != 3)
            load[0] = load[1] = load[2] = 0;
        fclose(la);
    }
    printf("\n%ld cores; load average at the end %.2f %.2f %.2f\n", cores, load[0], load[1],
           load[2]);
    printf("| 1280x720, %d-triangle cloth, median of %d | wall clock | CPU seconds per frame |\n",
           cloth->nt, RUNS);
    printf("|---|---|---|\n");
    printf("| embree, 16 samples/pixel, 2 bounces: seconds per frame | %.2f | %.2f |\n", embree_s,
           embree_cpu);
    printf("| embree: million rays per second (%lld rays a frame) | %.2f | %.2f per CPU second |\n",
           nrays, embree_rays * 1e-6, (double)nrays / embree_cpu * 1e-6);
    printf("| preview, 4x multisampling: frames per second | %.1f | %.3f |\n",
           median(fps[1], RUNS), 1.0 / median(fps_cpu[1], RUNS));
    printf("| preview, 1 sample: frames per second | %.1f | %.3f |\n", median(fps[0], RUNS),
           1.0 / median(fps_cpu[0], RUNS));
    cs_image_destroy(img);
    cs_trimesh_destroy(cloth);
    cs_trimesh_destroy(ballm);
    cs_trimesh_destroy(groundm);
    return 0;
}
