/* summary.c: DIR/summary.json, DIR/frames.jsonl and the stage table of
 * `clothsim run`. */
#include "app/summary.h"

#include "app/checkpoint.h"
#include "common/util.h"

#include <cJSON.h>
#include <errno.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

void cs_summary_init(cs_summary *s)
{
    memset(s, 0, sizeof *s);
    s->status = "running";
    s->failed_frame = -1;
    s->resumed_from = -1;
}

void cs_summary_free(cs_summary *s)
{
    if (s->records)
        fclose(s->records);
    s->records = NULL;
}

void cs_summary_take_timing(cs_summary *s, const cs_sim *sim)
{
    const cs_stage_timing *t = cs_sim_stage_timing(sim);
    const cs_comm_stats *c = cs_sim_stage_comm(sim);
    for (int i = 0; i < CS_STAGE_COUNT; i++) {
        cs_stage_timing ti = t ? t[i] : (cs_stage_timing){0, 0};
        cs_comm_stats ci = c ? c[i] : (cs_comm_stats){0, 0, 0};
        s->timing[i].seconds = s->base_timing[i].seconds + ti.seconds;
        s->timing[i].calls = s->base_timing[i].calls + ti.calls;
        s->comm[i].seconds = s->base_comm[i].seconds + ci.seconds;
        s->comm[i].bytes = s->base_comm[i].bytes + ci.bytes;
        s->comm[i].messages = s->base_comm[i].messages + ci.messages;
        s->bytes[i] = cs_sim_stage_bytes(sim, (cs_stage)i);
    }
    s->ranks = cs_sim_ranks(sim);
    s->threads = cs_parallel_threads();
    const cs_comm_stats *per_rank = cs_sim_rank_comm(sim);
    for (int r = 0; r < s->ranks && r < CS_SUMMARY_MAX_RANKS; r++)
        s->rank_comm[r] = per_rank[r];
}

void cs_summary_totals(const cs_summary *s, double *out)
{
    for (int i = 0; i < CS_STAGE_COUNT; i++) {
        double *o = out + 5 * i;
        o[0] = s->timing[i].seconds;
        o[1] = (double)s->timing[i].calls;
        o[2] = s->comm[i].seconds;
        o[3] = (double)s->comm[i].bytes;
        o[4] = (double)s->comm[i].messages;
    }
    double *o = out + 5 * CS_STAGE_COUNT;
    o[0] = s->total_seconds;
    o[1] = s->simulation_seconds;
    o[2] = s->output_seconds;
}

void cs_summary_set_base(cs_summary *s, const double *in)
{
    for (int i = 0; i < CS_STAGE_COUNT; i++) {
        const double *t = in + 5 * i;
        s->base_timing[i] = (cs_stage_timing){t[0], (long)t[1]};
        s->base_comm[i] = (cs_comm_stats){t[2], (long)t[3], (long)t[4]};
        s->timing[i] = s->base_timing[i];
        s->comm[i] = s->base_comm[i];
    }
    const double *t = in + 5 * CS_STAGE_COUNT;
    s->base_seconds = t[0];
    s->total_seconds = t[0];
    s->simulation_seconds = t[1];
    s->output_seconds = t[2];
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
    if (s->step_limit)
        add_str(b, root, "step_limit", s->step_limit);
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
    if (s->scripts) {
        add_str(b, root, "script_zones", s->script_zones);
        add_num(b, root, "script_lag_max", s->script_lag_max);
    }
    add_num(b, root, "total_seconds", s->total_seconds);
    add_num(b, root, "simulation_seconds", s->simulation_seconds);
    add_num(b, root, "output_seconds", s->output_seconds);

    add_str(b, root, "frames_file", "frames.jsonl");
    if (cs_checkpoint_file_name()) /* none without HDF5 */
        add_str(b, root, "state_file", cs_checkpoint_file_name());
    add_str(b, root, "state_hash_algorithm", CS_STATE_HASH_ALGORITHM);
    if (s->initial_hash[0])
        add_str(b, root, "initial_state_hash", s->initial_hash);
    if (s->resumed_from >= 0)
        add_num(b, root, "resumed_from_frame", s->resumed_from);
    if (s->carried_frames > 0) /* frames 1.. carried from another run (their records say which) */
        add_num(b, root, "carried_frames", s->carried_frames);
    return root;
}

/* One frame's record: a line of frames.jsonl, an entry of "frames". */
static cJSON *frame_json(const cs_summary *s, const cs_frame_record *f, builder *b)
{
    cJSON *o = cJSON_CreateObject();
    if (!o) {
        b->ok = false;
        return NULL;
    }
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
        add_num(b, o, "held_zones", (double)st->held_zones);
        add_num(b, o, "projected_zones", (double)st->projected_zones);
        add_num(b, o, "rewinds", (double)st->rewinds);
        add_num(b, o, "pair_searches", (double)st->pair_searches);
        add_num(b, o, "pair_traversals", (double)st->pair_traversals);
    }
    if (s->scripts)
        add_num(b, o, "script_lag", st->script_lag);
    if (st->intersections >= 0)
        add_num(b, o, "intersections", (double)st->intersections);
    if (f->body_penetration >= 0)
        add_num(b, o, "body_penetration_max", f->body_penetration);
    add_num(b, o, "seconds", f->seconds);
    add_str(b, o, "state_hash", f->state_hash);
    if (f->resampled_from)
        add_str(b, o, "resampled_from", f->resampled_from);
    return o;
}

/* ------------------------------------------------------------ frames.jsonl */

/* Calls fn on each whole line of text (a trailing partial line, left by a
 * run killed mid-write, is not one). Stops at the first nonzero return. */
static int each_line(char *text, int (*fn)(char *line, void *ctx), void *ctx)
{
    for (char *line = text, *end; (end = strchr(line, '\n')) != NULL; line = end + 1) {
        *end = '\0';
        int rc = fn(line, ctx);
        *end = '\n';
        if (rc)
            return rc;
    }
    return 0;
}

typedef struct trim_ctx {
    int keep, next;       /* keep frames 1..keep; the frame expected next */
    int carried;          /* of those, records of frames carried over */
    size_t kept;          /* bytes of text kept */
    const char *text;
} trim_ctx;

static int trim_line(char *line, void *ctx)
{
    trim_ctx *t = ctx;
    cJSON *o = cJSON_Parse(line);
    const cJSON *f = o ? cJSON_GetObjectItemCaseSensitive(o, "frame") : NULL;
    int frame = cJSON_IsNumber(f) ? f->valueint : -1;
    bool carried = o && cJSON_GetObjectItemCaseSensitive(o, "resampled_from");
    cJSON_Delete(o);
    if (frame != t->next)
        return -1; /* damaged, or a frame missing: t->next names it */
    t->next++;
    t->carried += carried;
    t->kept = (size_t)(line - t->text) + strlen(line) + 1;
    return t->next > t->keep ? 1 : 0;
}

int cs_summary_open_records(cs_summary *s, const char *path, int keep, char *err,
                            size_t errlen)
{
    s->records_path = path;
    s->nframes = 0;
    s->records_size = 0;
    if (keep > 0) { /* resuming: keep frames 1..keep, whole lines only */
        size_t len = 0;
        char *text = cs_file_read_all(path, &len);
        if (!text) {
            snprintf(err, errlen, "cannot read %s: %s", path, strerror(errno));
            return -1;
        }
        trim_ctx t = {keep, 1, 0, 0, text};
        each_line(text, trim_line, &t);
        if (t.next <= keep) {
            snprintf(err, errlen, "%s: the record of frame %d is missing or damaged; the run "
                     "cannot be continued", path, t.next);
            free(text);
            return -1;
        }
        int rc = cs_file_write_atomic(path, text, t.kept, err, errlen);
        free(text);
        if (rc != 0)
            return -1;
        s->nframes = keep;
        s->carried_frames = t.carried;
        s->records_size = (long)t.kept;
    }
    s->records = fopen(path, keep > 0 ? "ab" : "wb");
    if (!s->records) {
        snprintf(err, errlen, "cannot write %s: %s", path, strerror(errno));
        return -1;
    }
    return 0;
}

int cs_summary_add_frame(cs_summary *s, const cs_frame_record *frame, char *err, size_t errlen)
{
    builder b = {true};
    if (frame->stats.script_lag > s->script_lag_max)
        s->script_lag_max = frame->stats.script_lag;
    cJSON *o = frame_json(s, frame, &b);
    char *text = b.ok ? cJSON_PrintUnformatted(o) : NULL;
    cJSON_Delete(o);
    if (!text) {
        snprintf(err, errlen, "cannot write %s: out of memory", s->records_path);
        return -1;
    }
    errno = 0;
    size_t len = strlen(text);
    bool ok = s->records && fputs(text, s->records) >= 0 && fputc('\n', s->records) != EOF &&
              fflush(s->records) == 0;
    free(text);
    if (!ok) {
        snprintf(err, errlen, "cannot write %s: %s", s->records_path,
                 strerror(errno ? errno : EIO));
        if (s->records) { /* no half record: back to the last whole one */
            clearerr(s->records);
            if (ftruncate(fileno(s->records), s->records_size) != 0)
                fprintf(stderr, "clothsim: cannot cut %s back to its last whole record: %s\n",
                        s->records_path, strerror(errno));
        }
        return -1;
    }
    s->records_size += (long)len + 1;
    s->nframes++;
    if (frame->resampled_from) /* carried over, not simulated */
        s->carried_frames++;
    else
        s->run_frames++;
    s->run_steps += frame->stats.steps;
    return 0;
}

typedef struct gather_ctx {
    builder *b;
    cJSON *frames;
} gather_ctx;

static int gather_line(char *line, void *ctx)
{
    gather_ctx *g = ctx;
    cJSON *o = cJSON_Parse(line);
    if (!o)
        return -1;
    append(g->b, g->frames, o);
    return 0;
}

int cs_summary_write(const cs_summary *s, const char *path, bool final, char *err,
                     size_t errlen)
{
    builder b = {true};
    cJSON *root = build_json(s, &b);
    if (final && b.ok) { /* the records on disk are the run's frames */
        size_t len = 0;
        char *records = s->records_path ? cs_file_read_all(s->records_path, &len) : NULL;
        gather_ctx g = {&b, add_array(&b, root, "frames")};
        if (s->records_path && !records) {
            snprintf(err, errlen, "cannot read %s: %s", s->records_path, strerror(errno));
            cJSON_Delete(root);
            return -1;
        }
        if (records && each_line(records, gather_line, &g) != 0) {
            snprintf(err, errlen, "%s: a record is damaged", s->records_path);
            free(records);
            cJSON_Delete(root);
            return -1;
        }
        free(records);
    }
    char *text = b.ok ? cJSON_Print(root) : NULL;
    cJSON_Delete(root);
    if (!text) {
        snprintf(err, errlen, "cannot write %s: out of memory", path);
        return -1;
    }
    size_t len = strlen(text);
    text[len] = '\n'; /* in place of the terminator: the file ends with a newline */
    int rc = cs_file_write_atomic(path, text, len + 1, err, errlen);
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

    int simulated = s->nframes - s->carried_frames;
    fprintf(out, "\nwall time %.3f s (simulation %.3f s, output %.3f s)\n",
            s->total_seconds, s->simulation_seconds, s->output_seconds);
    if (simulated > 0) {
        fprintf(out, "simulation time per frame %.3f s over %d frame%s",
                s->simulation_seconds / simulated, simulated, simulated == 1 ? "" : "s");
        if (s->run_steps != (long)s->steps_per_frame * s->run_frames)
            /* the damped limit chose the step before every outer step */
            fprintf(out, " (%.1f steps a frame over the %d this command simulated, each step "
                    "chosen from the cloth's tension; %d of %.3g s at rest)\n",
                    (double)s->run_steps / s->run_frames, s->run_frames, s->steps_per_frame,
                    s->dt);
        else if (s->run_frames > 0)
            fprintf(out, " (%d steps of %.3g s each)\n", s->steps_per_frame, s->dt);
        else
            fprintf(out, " (none simulated by this command)\n");
    } else {
        fprintf(out, "no frame simulated\n");
    }
}
