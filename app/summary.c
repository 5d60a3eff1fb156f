/* summary.c: DIR/summary.json and the stage table of `clothsim run`. */
#include "app/summary.h"

#include <cJSON.h>
#include <errno.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

void cs_summary_init(cs_summary *s)
{
    memset(s, 0, sizeof *s);
    s->status = "running";
    s->failed_frame = -1;
}

void cs_summary_free(cs_summary *s)
{
    free(s->frames);
    s->frames = NULL;
    s->nframes = s->capacity = 0;
}

int cs_summary_add_frame(cs_summary *s, const cs_frame_record *frame)
{
    if (s->nframes == s->capacity) {
        int cap = s->capacity ? 2 * s->capacity : 64;
        cs_frame_record *grown = realloc(s->frames, (size_t)cap * sizeof *grown);
        if (!grown)
            return -1;
        s->frames = grown;
        s->capacity = cap;
    }
    s->frames[s->nframes++] = *frame;
    return 0;
}

void cs_summary_take_timing(cs_summary *s, const cs_sim *sim)
{
    const cs_stage_timing *t = cs_sim_stage_timing(sim);
    const cs_comm_stats *c = cs_sim_stage_comm(sim);
    for (int i = 0; i < CS_STAGE_COUNT; i++) {
        s->timing[i] = t ? t[i] : (cs_stage_timing){0, 0};
        s->bytes[i] = cs_sim_stage_bytes(sim, (cs_stage)i);
        s->comm[i] = c ? c[i] : (cs_comm_stats){0, 0, 0};
    }
    s->ranks = cs_sim_ranks(sim);
    s->threads = cs_parallel_threads();
    const cs_comm_stats *per_rank = cs_sim_rank_comm(sim);
    for (int r = 0; r < s->ranks && r < CS_SUMMARY_MAX_RANKS; r++)
        s->rank_comm[r] = per_rank[r];
}

static double stage_total(const cs_summary *s)
{
    double total = 0;
    for (int i = 0; i < s->plan.nstages; i++)
        total += s->timing[s->plan.stages[i]].seconds;
    return total;
}

/* ------------------------------------------------------------------ JSON */

/* Adders that remember whether anything failed (cJSON returns NULL when
 * memory runs out), so the document is checked once at the end. */
typedef struct builder {
    bool ok;
} builder;

static void add_num(builder *b, cJSON *obj, const char *key, double v)
{
    if (!cJSON_AddNumberToObject(obj, key, v))
        b->ok = false;
}

static void add_str(builder *b, cJSON *obj, const char *key, const char *v)
{
    if (!(v ? cJSON_AddStringToObject(obj, key, v) : cJSON_AddNullToObject(obj, key)))
        b->ok = false;
}

static cJSON *add_array(builder *b, cJSON *obj, const char *key)
{
    cJSON *a = cJSON_AddArrayToObject(obj, key);
    if (!a)
        b->ok = false;
    return a;
}

static void append(builder *b, cJSON *array, cJSON *item)
{
    if (!array || !item || !cJSON_AddItemToArray(array, item)) {
        cJSON_Delete(item);
        b->ok = false;
    }
}

static cJSON *build_json(const cs_summary *s, builder *b)
{
    cJSON *root = cJSON_CreateObject();
    if (!root) {
        b->ok = false;
        return NULL;
    }
    add_str(b, root, "scene", s->scene);
    add_str(b, root, "scene_file", s->scene_file);
    cJSON *overrides = add_array(b, root, "overrides");
    for (int i = 0; i < s->noverrides; i++)
        append(b, overrides, cJSON_CreateString(s->overrides[i]));
    add_str(b, root, "clothsim_version", s->version);
    add_str(b, root, "status", s->status);
    if (s->error)
        add_str(b, root, "error", s->error);
    if (s->failed_frame >= 0)
        add_num(b, root, "failed_frame", s->failed_frame);
    add_str(b, root, "output_dir", s->output_dir);
    add_str(b, root, "format", s->format);
    add_num(b, root, "frames_requested", s->frames_requested);
    add_num(b, root, "frames_written", s->frames_written);
    add_num(b, root, "fps", s->fps);
    add_num(b, root, "dt", s->dt);
    add_num(b, root, "steps_per_frame", s->steps_per_frame);
    add_num(b, root, "particles", s->particles);
    add_num(b, root, "triangles", s->triangles);
    add_num(b, root, "springs", s->springs);
    add_num(b, root, "ranks", s->ranks > 0 ? s->ranks : 1);
    add_num(b, root, "threads", s->threads > 0 ? s->threads : 1);

    cJSON *plan = add_array(b, root, "plan");
    for (int i = 0; i < s->plan.nstages; i++)
        append(b, plan, cJSON_CreateString(cs_stage_name(s->plan.stages[i])));

    double total = stage_total(s);
    cJSON *stages = add_array(b, root, "stages");
    for (int i = 0; i < s->plan.nstages; i++) {
        cs_stage st = s->plan.stages[i];
        cJSON *o = cJSON_CreateObject();
        if (o) {
            add_str(b, o, "name", cs_stage_name(st));
            add_num(b, o, "seconds", s->timing[st].seconds);
            add_num(b, o, "share", total > 0 ? s->timing[st].seconds / total : 0.0);
            add_num(b, o, "calls", (double)s->timing[st].calls);
            add_num(b, o, "bytes", (double)s->bytes[st]);
            add_num(b, o, "communication_seconds", s->comm[st].seconds);
            add_num(b, o, "bytes_sent", (double)s->comm[st].bytes);
            add_num(b, o, "messages_sent", (double)s->comm[st].messages);
        }
        append(b, stages, o);
    }
    cJSON *ranks = add_array(b, root, "communication");
    for (int r = 0; r < s->ranks && r < CS_SUMMARY_MAX_RANKS; r++) {
        cJSON *o = cJSON_CreateObject();
        if (o) {
            add_num(b, o, "rank", r);
            add_num(b, o, "seconds", s->rank_comm[r].seconds);
            add_num(b, o, "bytes_sent", (double)s->rank_comm[r].bytes);
            add_num(b, o, "messages_sent", (double)s->rank_comm[r].messages);
        }
        append(b, ranks, o);
    }
    add_num(b, root, "total_seconds", s->total_seconds);
    add_num(b, root, "simulation_seconds", s->simulation_seconds);
    add_num(b, root, "output_seconds", s->output_seconds);

    cJSON *frames = add_array(b, root, "frames");
    for (int i = 0; i < s->nframes; i++) {
        const cs_frame_record *f = &s->frames[i];
        cJSON *o = cJSON_CreateObject();
        if (o) {
            add_num(b, o, "frame", f->frame);
            add_num(b, o, "time", f->time);
            const cs_frame_stats *st = &f->stats;
            add_num(b, o, "steps", st->steps);
            add_num(b, o, "dt", st->dt);
            add_num(b, o, "cg_iterations", (double)st->cg_iterations);
            add_num(b, o, "body_contacts", (double)st->body_contacts);
            add_num(b, o, "max_speed", st->max_speed);
            if (s->self_collision) {
                add_num(b, o, "repulsion_pairs", (double)st->repulsion_pairs);
                add_num(b, o, "repulsions", (double)st->repulsions);
                add_num(b, o, "collisions", (double)st->collisions);
                add_num(b, o, "collision_passes", (double)st->collision_passes);
                add_num(b, o, "impact_zones", (double)st->impact_zones);
                add_num(b, o, "max_zone_size", (double)st->max_zone_size);
                add_num(b, o, "rewinds", (double)st->rewinds);
            }
            if (st->intersections >= 0)
                add_num(b, o, "intersections", (double)st->intersections);
            if (f->body_penetration >= 0)
                add_num(b, o, "body_penetration_max", f->body_penetration);
            add_num(b, o, "seconds", f->seconds);
        }
        append(b, frames, o);
    }
    return root;
}

int cs_summary_write(const cs_summary *s, const char *path, char *err, size_t errlen)
{
    builder b = {true};
    cJSON *root = build_json(s, &b);
    char *text = b.ok ? cJSON_Print(root) : NULL;
    cJSON_Delete(root);
    if (!text) {
        snprintf(err, errlen, "cannot write %s: out of memory", path);
        return -1;
    }

    size_t len = strlen(path);
    char *tmp = malloc(len + 5);
    if (!tmp) {
        free(text);
        snprintf(err, errlen, "cannot write %s: out of memory", path);
        return -1;
    }
    memcpy(tmp, path, len);
    memcpy(tmp + len, ".tmp", 5);

    int rc = -1;
    FILE *fp = fopen(tmp, "w");
    if (!fp) {
        snprintf(err, errlen, "cannot write %s: %s", tmp, strerror(errno));
    } else {
        bool written = fputs(text, fp) >= 0 && fputc('\n', fp) != EOF;
        int saved = errno;
        if (fclose(fp) != 0 && written) {
            written = false;
            saved = errno;
        }
        if (!written)
            snprintf(err, errlen, "cannot write %s: %s", tmp, strerror(saved));
        else if (rename(tmp, path) != 0)
            snprintf(err, errlen, "cannot rename %s to %s: %s", tmp, path, strerror(errno));
        else
            rc = 0;
        if (rc != 0)
            remove(tmp);
    }
    free(tmp);
    free(text);
    return rc;
}

/* ----------------------------------------------------------------- table */

void cs_summary_print_table(const cs_summary *s, FILE *out)
{
    int width = (int)strlen("stage");
    for (int i = 0; i < s->plan.nstages; i++) {
        int n = (int)strlen(cs_stage_name(s->plan.stages[i]));
        if (n > width)
            width = n;
    }
    double total = stage_total(s);
    long calls_total = 0;

    /* "comm": of the stage's seconds, those spent in messages (Table 2's
     * communication row, split by stage); with several ranks the seconds
     * are the slowest rank's */
    double comm_total = 0;
    long bytes_total = 0;
    fprintf(out, "\n%-*s  %10s  %10s  %7s  %9s  %12s\n", width, "stage", "seconds", "comm",
            "share", "calls", "bytes sent");
    for (int i = 0; i < s->plan.nstages; i++) {
        cs_stage st = s->plan.stages[i];
        const cs_stage_timing *t = &s->timing[st];
        fprintf(out, "%-*s  %10.3f  %10.3f  %6.1f%%  %9ld  %12ld\n", width, cs_stage_name(st),
                t->seconds, s->comm[st].seconds,
                total > 0 ? 100.0 * t->seconds / total : 0.0, t->calls, s->comm[st].bytes);
        calls_total += t->calls;
        comm_total += s->comm[st].seconds;
        bytes_total += s->comm[st].bytes;
    }
    fprintf(out, "%-*s  %10.3f  %10.3f  %6.1f%%  %9ld  %12ld\n", width, "all stages", total,
            comm_total, total > 0 ? 100.0 : 0.0, calls_total, bytes_total);
    if (s->ranks > 1)
        fprintf(out, "%d ranks; summary.json lists the bytes and messages each sent\n",
                s->ranks);
    if (s->threads > 1)
        fprintf(out, "%d threads per rank\n", s->threads);

    int simulated = s->nframes;
    fprintf(out, "\nwall time %.3f s (simulation %.3f s, output %.3f s)\n",
            s->total_seconds, s->simulation_seconds, s->output_seconds);
    if (simulated > 0)
        fprintf(out, "simulation time per frame %.3f s over %d frame%s (%d steps of %.3g s each)\n",
                s->simulation_seconds / simulated, simulated, simulated == 1 ? "" : "s",
                s->steps_per_frame, s->dt);
    else
        fprintf(out, "no frame simulated\n");
}
