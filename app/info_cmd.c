/* info_cmd.c: `clothsim info DIR`: what a run did, frame by frame, from
 * its folder: DIR/summary.json (the scene, the format, the run's status),
 * DIR/frames.jsonl (a record per simulated frame: time, max_speed, and
 * intersections when the scene asked for self_collision.verify) and the
 * frame files. A table on stdout and a PLplot figure, DIR/info.png.
 *
 * What the records lack is computed, and the table says so: intersecting
 * pairs by the verifier on the frame's mesh (unless --no-verify); kinetic
 * energy and a speed from the positions of consecutive frames (the records
 * keep only the largest end-of-frame speed, the state only the last frame's
 * velocities), with the masses the scene gives; the gravitational potential
 * energy -m g.x (elastic energy is not computed).
 */
#include "app/info_cmd.h"

#include "app/cli.h"
#include "app/outdir.h"
#include "app/run.h"
#include "app/sweep_cmd.h"
#include "common/util.h"
#include "import/import.h"
#include "sim/sim.h"

#include <cJSON.h>
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define ERRLEN 1024

void cs_info_help(FILE *out)
{
    fputs("usage: clothsim info DIR [options]\n"
          "\n"
          "Prints a table of the run in DIR (the folder 'clothsim run' wrote), a row per\n"
          "frame: frame, time, status, intersecting triangle pairs and where that number\n"
          "comes from (rec: DIR/frames.jsonl, when the scene had self_collision.verify;\n"
          "verifier: counted here on the frame's mesh; -: skipped), kinetic and\n"
          "gravitational potential energy, the largest speed the run recorded\n"
          "(max_speed in frames.jsonl: the simulation's velocities at the frame's end)\n"
          "and the largest speed from the positions of this frame and the one before\n"
          "(|dx| fps: the mean over the frame). The kinetic energy is from those mean\n"
          "velocities too (the run does not store each frame's velocities), with the\n"
          "masses of the run's scene; the potential is -m g.x, gravity only. Then\n"
          "draws the same columns against time as DIR/info.png (PLplot).\n"
          "\n"
          "options:\n"
          "      --no-verify  do not count pairs the records lack (faster on big frames)\n"
          "      --no-plot    do not write DIR/info.png\n"
          "  -h, --help       show this help\n"
          "\n"
          "exit status:\n"
          "  0    the table printed (and info.png written)\n"
          "  2    bad command line, DIR is not a run folder, or a frame is unreadable\n"
          "  4    out of memory, or info.png could not be written\n",
          out);
}

static const cs_cli CLI = {"info", NULL, cs_info_help, CS_EXIT_INPUT};

/* One row of the table. */
typedef struct row {
    int frame;
    double time;
    const char *status;
    long pairs;          /* -1: not known */
    const char *source;  /* "rec", "verifier", "-" */
    double kinetic;      /* J, NAN: not known */
    double potential;    /* J */
    double max_speed;    /* the record's, NAN for none */
    double fd_speed;     /* from positions, NAN for frame 0 */
    double total;        /* kinetic + the potential at the frame's middle (the mean of
                            this frame's and the last's), J: the kinetic energy is of the
                            mean velocity over the frame, so they go together */
    bool have_file;
} row;

typedef struct info_ctx {
    row *rows;
    int nrows;
    char title[512];
} info_ctx;

static double num_of(const cJSON *o, const char *key, double def)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    return cJSON_IsNumber(v) ? v->valuedouble : def;
}

/* The vertex masses of every cloth, in particle order, as sim.c makes them. */
static double *scene_masses(const cs_scene *scene, int *nv_out)
{
    int nv = 0;
    for (int c = 0; c < scene->def.ncloths; c++)
        nv += scene->def.cloths[c].mesh->nv;
    double *mass = calloc((size_t)nv + 1, sizeof *mass);
    if (!mass)
        return NULL;
    int off = 0;
    for (int c = 0; c < scene->def.ncloths; c++) {
        const cs_cloth_def *cl = &scene->def.cloths[c];
        const cs_trimesh *m = cl->mesh;
        double *ms = mass + off;
        bool dens = cl->material.density > 0;
        for (int i = 0; i < m->nv; i++)
            ms[i] = dens ? 0 : cl->material.node_mass;
        for (int t = 0; dens && t < m->nt; t++) {
            const int *tri = m->tri + 3 * t;
            const double *a = m->x + 3 * tri[0], *b = m->x + 3 * tri[1], *d = m->x + 3 * tri[2];
            double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
            double e2[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
            double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                           e1[0] * e2[1] - e1[1] * e2[0]};
            double share =
                cl->material.density * 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) / 3.0;
            for (int k = 0; k < 3; k++)
                ms[tri[k]] += share;
        }
        for (int i = 0; i < m->nv; i++)
            if (!(ms[i] > 0))
                ms[i] = cl->material.node_mass;
        off += m->nv;
    }
    *nv_out = nv;
    return mass;
}

/* ------------------------------------------------------------------ plot */

/* DIR/info.png from the rows: the columns as series against time, NaN
 * where a row has no value (info_plot.c draws them). Returns 0, or -1
 * with err. */
static int write_plot(const char *path, const info_ctx *ctx, char *err, size_t errlen)
{
    int n = ctx->nrows;
    double *buf = calloc(7 * ((size_t)n + 1), sizeof *buf);
    if (!buf) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    double *t = buf, *pairs = t + n + 1, *ke = pairs + n + 1, *pe = ke + n + 1,
           *tot = pe + n + 1, *vs = tot + n + 1, *fd = vs + n + 1;
    double pe0 = NAN, tot0 = NAN;
    for (int i = 0; i < n; i++) {
        const row *r = &ctx->rows[i];
        t[i] = r->have_file || isfinite(r->max_speed) ? r->time : NAN;
        pairs[i] = r->pairs >= 0 ? (double)r->pairs : NAN;
        ke[i] = r->kinetic;
        if (isfinite(r->potential) && !isfinite(pe0))
            pe0 = r->potential;
        pe[i] = r->potential - pe0;
        if (isfinite(r->total) && !isfinite(tot0))
            tot0 = r->total;
        tot[i] = r->total - tot0;
        vs[i] = r->max_speed;
        fd[i] = r->fd_speed;
    }
    cs_info_figure fig = {ctx->title, n, t, pairs, ke, pe, tot, vs, fd};
    int rc = cs_info_plot(path, &fig, err, errlen);
    free(buf);
    return rc;
}

/* ------------------------------------------------------------------ main */

static void print_num(double v, const char *fmt)
{
    if (isfinite(v))
        printf(fmt, v);
    else
        printf(" %12s", "-");
}

int cs_info_main(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"no-verify", no_argument, NULL, 'v'},
        {"no-plot", no_argument, NULL, 'p'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    bool verify = true, plot = true;
    optind = 1;
    opterr = 0;
    int c, status = 0;
    while ((c = getopt_long(argc, argv, "h", longopts, NULL)) != -1) {
        switch (c) {
        case 'v': verify = false; break;
        case 'p': plot = false; break;
        case 'h': cs_info_help(stdout); return CS_EXIT_OK;
        default: return cs_cli_option_error(&CLI, c, argv);
        }
    }
    const char *dir = cs_cli_operand(&CLI, argc, argv, optind, "run folder", &status);
    if (!dir)
        return status;

    char err[ERRLEN] = "", path[4096];
    if (plot && cs_plot_available(err, sizeof err) != 0) { /* before the table */
        fprintf(stderr, "clothsim info: %s (--no-plot prints the table alone)\n", err);
        return CS_EXIT_OUTPUT;
    }
    cs_run_info info;
    if ((status = cs_run_info_read(dir, &info, err, sizeof err)) != CS_EXIT_OK) {
        fprintf(stderr, "clothsim info: %s\n", err);
        return status;
    }
    /* the run's status and failed frame */
    snprintf(path, sizeof path, "%s/summary.json", dir);
    size_t text_len = 0;
    char *text = cs_file_read_all(path, &text_len);
    cJSON *summary = text ? cJSON_Parse(text) : NULL;
    free(text);
    const cJSON *st = cJSON_GetObjectItemCaseSensitive(summary, "status");
    const char *run_status = cJSON_IsString(st) ? st->valuestring : "?";
    int failed_frame = (int)num_of(summary, "failed_frame", -1);

    cs_scene *scene = NULL;
    int rc = cs_scene_load(info.scene_file, info.noverrides, (const char *const *)info.overrides,
                           &scene, err, sizeof err);
    if (rc != CS_OK) {
        fprintf(stderr, "clothsim info: the run's scene %s does not load (%s): its cloths' "
                        "names and masses are needed to read the frames\n",
                info.scene_file, err);
        status = CS_EXIT_INPUT;
        goto done_early;
    }

    int nframes = info.frames_written;
    int nrows = nframes + (failed_frame >= nframes ? 1 : 0);
    row *rows = calloc((size_t)nrows + 1, sizeof *rows);
    int nv = 0;
    double *mass = scene_masses(scene, &nv);
    cs_frame_layout layout;
    memset(&layout, 0, sizeof layout);
    const char **names = calloc((size_t)scene->def.ncloths + 1, sizeof *names);
    cs_trimesh **meshes = calloc((size_t)scene->def.ncloths + 1, sizeof *meshes);
    double *x = malloc(3 * sizeof *x * ((size_t)nv + 1)),
           *prev = malloc(3 * sizeof *prev * ((size_t)nv + 1));
    int nt = 0;
    for (int k = 0; k < scene->def.ncloths; k++)
        nt += scene->def.cloths[k].mesh->nt;
    int *tri = malloc(3 * sizeof *tri * ((size_t)nt + 1));
    if (!rows || !mass || !names || !meshes || !x || !prev || !tri) {
        fprintf(stderr, "clothsim info: out of memory\n");
        status = CS_EXIT_OUTPUT;
        goto done;
    }
    for (int k = 0; k < scene->def.ncloths; k++)
        names[k] = scene->def.cloths[k].name;
    if (cs_frame_layout_init(&layout, info.format, scene->def.ncloths, names) != 0) {
        fprintf(stderr, "clothsim info: out of memory\n");
        status = CS_EXIT_OUTPUT;
        goto done;
    }
    {
        int t = 0, off = 0;
        for (int k = 0; k < scene->def.ncloths; k++) {
            const cs_trimesh *m = scene->def.cloths[k].mesh;
            for (int i = 0; i < 3 * m->nt; i++)
                tri[3 * t + i] = off + m->tri[i];
            t += m->nt;
            off += m->nv;
        }
    }
    for (int f = 0; f < nrows; f++) {
        rows[f] = (row){.frame = f, .time = info.fps > 0 ? f / info.fps : NAN,
                        .status = f == 0 ? "initial" : "ok", .pairs = -1, .source = "-",
                        .kinetic = NAN, .potential = NAN, .max_speed = NAN, .fd_speed = NAN,
                        .total = NAN};
        if (f >= nframes) {
            rows[f].status = run_status; /* the frame the run stopped in, unwritten */
            rows[f].frame = failed_frame;
        }
    }
    /* frames.jsonl: the records of frames 1.. */
    snprintf(path, sizeof path, "%s/frames.jsonl", dir);
    FILE *rec = fopen(path, "r");
    bool have_records = rec != NULL;
    if (rec) {
        char *line = NULL;
        size_t cap = 0;
        while (getline(&line, &cap, rec) > 0) {
            cJSON *o = cJSON_Parse(line);
            int f = (int)num_of(o, "frame", -1);
            if (o && f >= 1 && f < nframes) {
                rows[f].time = num_of(o, "time", rows[f].time);
                rows[f].max_speed = num_of(o, "max_speed", NAN);
                const cJSON *p = cJSON_GetObjectItemCaseSensitive(o, "intersections");
                if (cJSON_IsNumber(p)) {
                    rows[f].pairs = (long)p->valuedouble;
                    rows[f].source = "rec";
                }
            }
            cJSON_Delete(o);
        }
        free(line);
        fclose(rec);
    }
    /* the frame files */
    char frames_dir[4096];
    snprintf(frames_dir, sizeof frames_dir, "%s/frames", dir);
    for (int f = 0; f < nframes; f++) {
        if ((status = cs_frame_read(&layout, frames_dir, f, meshes, err, sizeof err)) !=
            CS_EXIT_OK) {
            fprintf(stderr, "clothsim info: frame %d: %s\n", f, err);
            goto done;
        }
        int off = 0;
        bool same = true;
        for (int k = 0; k < scene->def.ncloths; k++) {
            const cs_trimesh *m = meshes[k];
            if (!m || m->nv != scene->def.cloths[k].mesh->nv) {
                same = false;
                break;
            }
            memcpy(x + 3 * (size_t)off, m->x, 3 * sizeof *x * (size_t)m->nv);
            off += m->nv;
        }
        for (int k = 0; k < scene->def.ncloths; k++) {
            cs_trimesh_destroy(meshes[k]);
            meshes[k] = NULL;
        }
        if (!same) {
            fprintf(stderr, "clothsim info: frame %d of %s does not hold the scene's cloths "
                            "(vertex counts differ): the scene changed since the run\n",
                    f, dir);
            status = CS_EXIT_INPUT;
            goto done;
        }
        row *r = &rows[f];
        r->have_file = true;
        if (r->pairs < 0 && verify) {
            r->pairs = cs_count_intersections(nv, x, nt, tri);
            r->source = r->pairs >= 0 ? "verifier" : "-";
        }
        double pe = 0;
        for (int i = 0; i < nv; i++)
            for (int k = 0; k < 3; k++)
                pe -= mass[i] * scene->def.gravity[k] * x[3 * (size_t)i + k];
        r->potential = pe;
        if (f > 0 && info.fps > 0) {
            double ke = 0, vmax = 0;
            for (int i = 0; i < nv; i++) {
                double v2 = 0;
                for (int k = 0; k < 3; k++) {
                    double v = (x[3 * (size_t)i + k] - prev[3 * (size_t)i + k]) * info.fps;
                    v2 += v * v;
                }
                ke += 0.5 * mass[i] * v2;
                vmax = fmax(vmax, sqrt(v2));
            }
            r->kinetic = ke;
            r->fd_speed = vmax;
            r->total = ke + 0.5 * (pe + rows[f - 1].potential);
        } else if (f == 0) {
            r->kinetic = NAN; /* the initial velocity is the scene's, not a frame's */
        }
        double *tmp = prev;
        prev = x;
        x = tmp;
    }

    printf("run %s: scene %s, status %s, %d frame%s written%s\n", dir, info.source_file,
           run_status, nframes, nframes == 1 ? "" : "s", have_records ? "" : " (no frames.jsonl)");
    printf("pairs: intersecting triangle pairs (src rec: frames.jsonl, verifier: counted on the "
           "frame file%s); kinetic: from the positions of consecutive frames (mean velocity "
           "over the frame); potential: gravity, -m g.x; max_speed: frames.jsonl (velocities "
           "at the frame's end); fd_speed: largest |dx| fps between frames\n",
           verify ? "" : ", skipped by --no-verify");
    printf("%6s %12s %-11s %8s %-8s %12s %12s %12s %12s\n", "frame", "time_s", "status", "pairs",
           "src", "kinetic_J", "potential_J", "max_speed", "fd_speed");
    for (int f = 0; f < nrows; f++) {
        const row *r = &rows[f];
        printf("%6d", r->frame);
        print_num(r->time, " %12.6g");
        printf(" %-11s", r->status);
        if (r->pairs >= 0)
            printf(" %8ld", r->pairs);
        else
            printf(" %8s", "-");
        printf(" %-8s", r->source);
        print_num(r->kinetic, " %12.6g");
        print_num(r->potential, " %12.6g");
        print_num(r->max_speed, " %12.6g");
        print_num(r->fd_speed, " %12.6g");
        printf("\n");
    }
    if (plot) {
        info_ctx ctx = {rows, nrows, ""};
        snprintf(ctx.title, sizeof ctx.title, "%s (%s): intersecting pairs", scene->name,
                 run_status);
        snprintf(path, sizeof path, "%s/info.png", dir);
        if (write_plot(path, &ctx, err, sizeof err) != 0) {
            fprintf(stderr, "clothsim info: %s\n", err);
            status = CS_EXIT_OUTPUT;
            goto done;
        }
        printf("wrote %s\n", path);
    }
    status = CS_EXIT_OK;
done:
    cs_frame_layout_free(&layout);
    free(rows);
    free(mass);
    free(names);
    free(meshes);
    free(x);
    free(prev);
    free(tri);
    cs_scene_destroy(scene);
done_early:
    cJSON_Delete(summary);
    cs_run_info_free(&info);
    return status;
}
