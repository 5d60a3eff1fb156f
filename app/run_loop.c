/* run_loop.c: the frames of `clothsim run`: each simulated, then written
 * with its record, its state and the summary, and the end reported.
 *
 * Every file appears atomically, so whatever stops the run (instability, a
 * signal, a full disk) leaves complete frames and a summary that describes
 * exactly them.
 */
#include "app/run_internal.h"

#include "app/exit.h"
#include "app/export.h"
#include "app/progress.h"
#include "common/util.h"
#include "import/import.h"
#include "sim/sim.h"

#include <math.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

/* ---------------------------------------------------------------- signals */

static volatile sig_atomic_t interrupted = 0;

static void on_signal(int sig)
{
    interrupted = sig;
}

/* The first SIGINT/SIGTERM asks the run to stop after the current frame;
 * the handler then resets, so a second one ends the process at once. */
static void install_signal_handlers(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND | SA_RESTART;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    /* a file-size limit (ulimit -f) then fails the write (EFBIG), which is
     * reported with exit 4, instead of killing the run mid-file */
    signal(SIGXFSZ, SIG_IGN);
}

/* ----------------------------------------------------------------- output */

static int write_frame(run_state *r, int frame, char *err, size_t errlen)
{
    const double *x = cs_sim_positions(r->sim);
    int ncloths = cs_sim_cloth_count(r->sim);
    for (int c = 0; c < ncloths; c++) {
        const cs_trimesh *mesh = cs_sim_cloth_mesh(r->sim, c);
        r->views[c].x = x + 3 * (size_t)cs_sim_cloth_offset(r->sim, c);
        r->views[c].nv = mesh->nv;
        r->views[c].nt = mesh->nt;
        r->views[c].tri = mesh->tri;
    }
    double t0 = cs_now();
    int rc = cs_frame_write(&r->out.layout, r->frames_dir, frame, r->views, err, errlen);
    if (rc == CS_OK && r->render && cs_run_render_frame(r->render, r->sim, frame, err,
                                                               errlen) != 0)
        rc = CS_ERR_BAD_INPUT;
    r->summary.output_seconds += cs_now() - t0;
    if (rc == CS_OK)
        r->summary.frames_written = frame + 1;
    return rc;
}

/* The summary's wall time and stage table brought up to now */
static void take_totals(run_state *r)
{
    r->summary.total_seconds = r->summary.base_seconds + cs_now() - r->start;
    cs_summary_take_timing(&r->summary, r->sim);
}

/* While the status is "running" summary.json leaves the frame records to
 * frames.jsonl (a constant cost per frame); once it is final, whole. */
static int write_summary(run_state *r, char *err, size_t errlen)
{
    take_totals(r);
    bool final = strcmp(r->summary.status, "running") != 0;
    r->summary_at = cs_now();
    return cs_summary_write(&r->summary, r->summary_path, final, err, errlen);
}

/* Rank 0, after frame's file (and record): the state --resume continues
 * from (cs_sim_state_gather came first, on every rank). */
static int save_state(run_state *r, int frame, const char *hash, char *err, size_t errlen)
{
    /* the totals a resumed run carries on from are those of this frame
     * (the summary is written at most once a second, so its totals could
     * lag frames behind, and a resumed run's stage table lost them) */
    take_totals(r);
    double t0 = cs_now();
    int rc = cs_outdir_save_state(&r->out, &r->id, frame, hash, r->sim, &r->summary, err,
                                  errlen);
    r->summary.output_seconds += cs_now() - t0;
    return rc;
}

/* -------------------------------------------------------------- the run */

/* "frames 0 to 12 are", "frame 0 is", "no frame is": what a stopped run kept. */
static void frames_kept(int written, char *buf, size_t len)
{
    if (written > 1)
        snprintf(buf, len, "frames 0 to %d are", written - 1);
    else if (written == 1)
        snprintf(buf, len, "frame 0 is");
    else
        snprintf(buf, len, "no frame is");
}

/* Rank 0: a write failed; says what, and which frames are kept. */
static int output_failed(run_state *r, cs_progress *progress, const char *err, const char *what,
                         int frame)
{
    cs_summary *s = &r->summary;
    char kept[64];
    cs_progress_finish(progress);
    frames_kept(s->frames_written, kept, sizeof kept);
    fprintf(stderr, "clothsim: %s\nclothsim: %s; %s kept in %s\n", err, what, kept,
            r->frames_dir);
    s->status = "failed";
    s->error = what;
    s->failed_frame = frame;
    return CS_EXIT_OUTPUT;
}

/* Rank 0, after a frame simulated: the frame file, its record, the state
 * to resume from and the summary, in that order (a state is never ahead of
 * its frame and record). Returns CS_EXIT_OK to go on, a status to stop
 * with the report, or minus a status to stop without it. */
static int record_frame(run_state *r, int frame, const cs_frame_stats *stats, double seconds,
                        cs_progress *progress, double sim_start)
{
    char err[ERRLEN];
    cs_summary *s = &r->summary;
    if (interrupted) { /* arrived during the frame: write nothing more */
        s->status = "interrupted";
        return CS_EXIT_INTERRUPTED;
    }
    cs_frame_record rec = {
        .frame = frame,
        .time = cs_sim_time(r->sim),
        .stats = *stats,
        .seconds = seconds,
        .body_penetration = cs_plan_has(cs_sim_plan(r->sim), CS_STAGE_BODY_COLLISION)
                                ? cs_sim_body_penetration(r->sim)
                                : -1,
    };
    cs_state_hash(r->sim, rec.state_hash);
    if (write_frame(r, frame, err, sizeof err) != CS_OK)
        return output_failed(r, progress, err, "a frame file could not be written", frame);
    if (cs_summary_add_frame(s, &rec, err, sizeof err) != 0)
        return output_failed(r, progress, err, "the frame's record could not be written", frame);
    if (save_state(r, frame, rec.state_hash, err, sizeof err) != 0)
        return output_failed(r, progress, err, "the state to resume from could not be written",
                             frame);
    if (cs_outdir_sync(&r->out, false, err, sizeof err) != 0)
        return output_failed(r, progress, err, "the output could not be written to the disk",
                             frame);
    /* while running, at most once a second: frames.jsonl has every frame */
    if (cs_now() - r->summary_at >= 1.0 && write_summary(r, err, sizeof err) != 0) {
        cs_progress_finish(progress);
        fprintf(stderr, "clothsim: %s\n", err);
        return -CS_EXIT_OUTPUT;
    }
    cs_progress_frame(progress, frame, rec.time, cs_now() - sim_start);
    if (!interrupted)
        return CS_EXIT_OK;
    s->status = "interrupted"; /* the frame is kept; nothing more is simulated */
    return CS_EXIT_INTERRUPTED;
}

/* Rank 0, --start-from: frame 0 (this scene's start), then frames 1 to N
 * of the run carried over (start_from.h), each with a record that says so,
 * and frame N's state, which the run continues from: *first_frame = N.
 * Returns an exit status, with the reason printed. */
static int start_from_output(run_state *r, const char *run_dir, bool quiet, int *first_frame)
{
    char err[ERRLEN];
    cs_summary *s = &r->summary;
    int last = cs_start_from_frame(r->origin), status = CS_EXIT_OK;
    if (write_frame(r, 0, err, sizeof err) != CS_OK)
        status = CS_EXIT_OUTPUT;
    for (int f = 1; f <= last && status == CS_EXIT_OK; f++) {
        status = cs_start_from_load_frame(r->origin, f, r->sim, err, sizeof err);
        if (status != CS_EXIT_OK)
            break;
        cs_frame_record rec = {.frame = f, .time = cs_sim_time(r->sim), .body_penetration = -1,
                               .resampled_from = run_dir};
        rec.stats.intersections = -1;
        if (f == last) { /* the state simulated from: counted, as every frame is */
            rec.stats.intersections = cs_sim_count_intersections(r->sim);
            if (rec.stats.intersections != 0 && !r->scene->allow_intersecting_start) {
                snprintf(err, sizeof err, "--start-from %s: frame %d carried onto this cloth "
                         "has %ld intersecting triangle pairs (the finer triangles cut "
                         "across the run's creases, or its cloth intersected); "
                         "check.allow_intersecting_start: true starts from it anyway",
                         run_dir, f, rec.stats.intersections);
                status = CS_EXIT_INPUT;
                break;
            }
            /* a held vertex off its script would jump there in one step */
            int vertex;
            double reach, off = cs_sim_script_offset(r->sim, &vertex);
            cs_sim_script_step_cap(r->sim, &reach);
            if (off > reach) {
                snprintf(err, sizeof err, "--start-from %s: scripted particle %d of this scene "
                         "is %.3g m from where its script puts it at t=%.6g s (more than its "
                         "script reach of %.3g m a step): the scene scripts vertices "
                         "the run did not (a selection that takes more vertices at this "
                         "resolution?)", run_dir, vertex, off, cs_sim_time(r->sim), reach);
                status = CS_EXIT_INPUT;
                break;
            }
        }
        cs_state_hash(r->sim, rec.state_hash);
        if (write_frame(r, f, err, sizeof err) != CS_OK ||
            cs_summary_add_frame(s, &rec, err, sizeof err) != 0 ||
            (f == last && save_state(r, f, rec.state_hash, err, sizeof err) != 0))
            status = CS_EXIT_OUTPUT;
    }
    if (status != CS_EXIT_OK) {
        fprintf(stderr, "clothsim: %s\n", err);
        s->status = "failed";
        s->error = "the run to start from could not be carried over";
        write_summary(r, err, sizeof err);
        return status;
    }
    if (!quiet)
        fprintf(stderr, "clothsim: starting after frame %d (t=%.6g s) of %s, carried onto %d "
                "particles\n", last, cs_sim_time(r->sim), run_dir, cs_sim_particle_count(r->sim));
    *first_frame = last;
    return CS_EXIT_OK;
}

/* Rank 0, before the first frame simulated: frame 0 and its state, or
 * after --resume only the summary. Returns as record_frame does. */
static int start_output(run_state *r, cs_progress *progress)
{
    char err[ERRLEN];
    if (r->first_frame == 0 && write_frame(r, 0, err, sizeof err) != CS_OK)
        return output_failed(r, progress, err, "a frame file could not be written", 0);
    if (r->first_frame == 0 && save_state(r, 0, r->summary.initial_hash, err, sizeof err) != 0)
        return output_failed(r, progress, err, "the state to resume from could not be written",
                             0);
    /* before any frame is simulated: the folder runs, renders and resumes
     * on its own (after --resume with the frames asked for now) */
    if (cs_outdir_write_scene(&r->out, r->scene, err, sizeof err) != 0)
        return output_failed(r, progress, err, "the resolved scene could not be written",
                             r->first_frame);
    if (write_summary(r, err, sizeof err) != 0) {
        fprintf(stderr, "clothsim: %s\n", err);
        return -CS_EXIT_OUTPUT; /* stop without the report */
    }
    return CS_EXIT_OK;
}

/* Rank 0, after the last frame: DIR/cloth.usda and the point caches
 * (output.usd, output.pc2) of the frames written, those of a run that
 * stopped early too. Returns the run's status, or CS_EXIT_OUTPUT when a
 * run that was ok could not write them. */
static int export_frames(run_state *r, int status)
{
    cs_export_what what = {r->scene->output_usd, r->scene->output_pc2};
    cs_summary *s = &r->summary;
    if ((!what.usd && !what.pc2) || s->frames_written < 1)
        return status;
    char err[ERRLEN];
    double t0 = cs_now();
    int rc = cs_export_run(r->scene, r->format, r->out.dir, s->frames_written, r->scene->def.fps,
                           what, NULL, err, sizeof err);
    s->output_seconds += cs_now() - t0;
    if (rc != CS_EXIT_OK)
        fprintf(stderr, "clothsim: %s\n", err);
    if (rc == CS_EXIT_OK || status != CS_EXIT_OK)
        return status; /* the run's own failure comes first */
    s->status = "failed";
    s->error = "the USD stage or the point caches could not be written";
    return CS_EXIT_OUTPUT;
}

int cs_run_simulate(run_state *r, const run_options *o)
{
    char err[ERRLEN];
    cs_summary *s = &r->summary;
    bool root = cs_sim_rank(r->sim) == 0;
    int status = CS_EXIT_OK;

    install_signal_handlers();
    if (root)
        status = cs_outdir_start(&r->out, o->resume, o->quiet, &r->id, r->sim, &r->summary,
                                 r->scene->frames, &r->first_frame);
    if (root && status == CS_EXIT_OK && r->origin)
        status = start_from_output(r, o->start_from, o->quiet, &r->first_frame);
    if ((status = cs_sim_agree(r->sim, status)) != CS_EXIT_OK)
        return status;
    r->first_frame = cs_sim_agree(r->sim, r->first_frame);
    if ((o->resume || o->start_from) && cs_sim_state_scatter(r->sim) != CS_OK) {
        /* every rank takes it */
        if (root)
            fprintf(stderr, "clothsim: out of memory\n");
        return CS_EXIT_OUTPUT;
    }

    cs_progress progress;
    cs_progress_init(&progress, stderr, o->quiet || !root, r->first_frame, r->scene->frames);

    cs_sim_state_gather(r->sim);
    if (root) {
        if (interrupted) {
            s->status = "interrupted";
            status = CS_EXIT_INTERRUPTED;
        } else {
            status = start_output(r, &progress);
        }
    }
    if ((status = cs_sim_agree(r->sim, status)) < 0)
        return -status;

    cs_progress_frame(&progress, r->first_frame, cs_sim_time(r->sim), 0.0);
    double sim_start = cs_now();
    for (int frame = r->first_frame + 1; status == CS_EXIT_OK && frame <= r->scene->frames;
         frame++) {
        cs_frame_stats stats;
        memset(&stats, 0, sizeof stats);
        double t0 = cs_now();
        int rc = cs_sim_advance_frame(r->sim, &stats);
        double seconds = cs_now() - t0;
        s->simulation_seconds += seconds;

        if (rc == CS_ERR_UNSTABLE) { /* every rank sees the same rc */
            cs_progress_finish(&progress);
            char kept[64];
            frames_kept(s->frames_written, kept, sizeof kept);
            static char why[192]; /* lives as long as the summary that points at it */
            const char *stage = "?";
            double speed = 0, limit = 0;
            if (!cs_sim_runaway(r->sim, &stage, &speed, &limit))
                snprintf(why, sizeof why, "NaN or runaway velocity");
            else if (isfinite(speed))
                snprintf(why, sizeof why,
                         "speed %.3g m/s after stage %s, beyond the %.3g m/s the scene's "
                         "gravity, bodies, scripts and wind can explain", speed, stage, limit);
            else
                snprintf(why, sizeof why, "NaN or infinite velocity after stage %s", stage);
            if (root)
                fprintf(stderr,
                        "clothsim: the simulation became unstable in frame %d (t=%.4g s): "
                        "%s; %s in %s\n",
                        frame, cs_sim_time(r->sim), why, kept, r->frames_dir);
            s->status = "unstable";
            s->error = why;
            s->failed_frame = frame;
            status = CS_EXIT_UNSTABLE;
            break;
        }
        if (rc == CS_ERR_SCRIPT) { /* every rank sees the same rc */
            cs_progress_finish(&progress);
            char kept[64];
            frames_kept(s->frames_written, kept, sizeof kept);
            static char why[1024]; /* lives as long as the summary that points at it */
            if (!cs_sim_script_conflict(r->sim, why, sizeof why))
                snprintf(why, sizeof why, "no collision-free state follows the scripts");
            if (root)
                fprintf(stderr, "clothsim: %s: frame %d cannot follow its script: %s; %s in %s\n",
                        r->scene->path, frame, why, kept, r->frames_dir);
            s->status = "unstable";
            s->error = why;
            s->failed_frame = frame;
            status = CS_EXIT_UNSTABLE;
            break;
        }
        if (rc != CS_OK) {
            cs_progress_finish(&progress);
            if (root)
                fprintf(stderr, "clothsim: frame %d failed (%s)\n", frame,
                        cs_status_message(rc));
            s->status = "failed";
            s->error = cs_status_message(rc);
            s->failed_frame = frame;
            status = cs_exit_status(rc);
            break;
        }
        cs_sim_state_gather(r->sim); /* the state to resume from, on rank 0 */
        if (root)
            status = record_frame(r, frame, &stats, seconds, &progress, sim_start);
        if ((status = cs_sim_agree(r->sim, status)) < 0)
            return -status;
    }
    cs_progress_finish(&progress);
    if (!root)
        return status;

    if (status == CS_EXIT_OK)
        s->status = "ok";
    if (status == CS_EXIT_INTERRUPTED) {
        char kept[64];
        frames_kept(s->frames_written, kept, sizeof kept);
        fprintf(stderr, "clothsim: interrupted; %s in %s\n", kept, r->frames_dir);
    }
    if (status == CS_EXIT_OK || status == CS_EXIT_UNSTABLE || status == CS_EXIT_INTERRUPTED)
        status = export_frames(r, status);
    if (write_summary(r, err, sizeof err) != 0 ||
        cs_outdir_sync(&r->out, true, err, sizeof err) != 0) {
        fprintf(stderr, "clothsim: %s\n", err);
        if (status == CS_EXIT_OK)
            status = CS_EXIT_OUTPUT;
    }
    cs_summary_print_table(s, stdout);
    if (status == CS_EXIT_OK)
        printf("wrote %d frame file%s to %s, summary in %s\n", s->frames_written,
               s->frames_written == 1 ? "" : "s", r->frames_dir, r->summary_path);
    if (status == CS_EXIT_OK && r->scene->output_usd)
        printf("the frames as one animated USD stage: %s/cloth.usda\n", r->out.dir);
    if (status == CS_EXIT_OK && r->scene->output_pc2)
        printf("Blender point caches and their rest poses: %s/pc2/\n", r->out.dir);
    fflush(stdout);
    return status;
}
