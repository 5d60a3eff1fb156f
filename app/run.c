/* run.c: `clothsim run SCENE`: load, simulate, write one mesh file per
 * frame, then report.
 *
 * Order of events: parse the command line (run_options.c); load the scene
 * with the overrides; build the plan and the simulation; (--plan: print and
 * stop, run_plan.c); check the start (input_check.h); then the frames
 * (run_loop.c): write frame 0, then per frame advance, write the mesh file,
 * rewrite summary.json.
 */
#include "app/run.h"
#include "app/run_internal.h"

#include "app/checkpoint.h"
#include "app/input_check.h"
#include "app/outdir.h"
#include "app/scene_render.h"
#include "app/summary.h"
#include "common/util.h"
#include "import/import.h"
#include "sim/sim.h"

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#ifndef CS_VERSION
#define CS_VERSION "unknown"
#endif

int cs_run_main(int argc, char **argv)
{
    run_options o;
    int status = cs_run_parse_options(argc, argv, &o);
    if (status >= 0) {
        cs_run_free_options(&o);
        return status;
    }

    run_state r;
    memset(&r, 0, sizeof r);
    r.out.lock = CS_DIR_LOCK_NONE;
    r.start = cs_now();
    cs_summary_init(&r.summary);
    cs_scene *scene = NULL;
    char err[ERRLEN] = "";

    /* every rank loads the scene: the same file gives the same result, so
     * only rank 0 speaks */
    bool root = cs_parallel_rank() == 0;
    cs_parallel_set_threads(o.threads);
    /* --format as an override loaded after the others (the resolved scene
     * holds it); the run's identity and summary keep the overrides given */
    if (o.format) {
        size_t len = strlen("output.format=") + strlen(o.format) + 1;
        if (!(o.format_override = malloc(len))) {
            fprintf(stderr, "clothsim: out of memory\n");
            status = CS_EXIT_OUTPUT;
            goto done;
        }
        snprintf(o.format_override, len, "output.format=%s", o.format);
        o.overrides[o.noverrides] = o.format_override;
    }
    int rc = cs_scene_load(o.scene_path, o.noverrides + (o.format ? 1 : 0),
                           (const char *const *)o.overrides, &scene, err, sizeof err);
    if (rc != CS_OK) {
        if (root)
            fprintf(stderr, "clothsim: %s\n", err[0] ? err : "cannot load the scene");
        status = cs_exit_status(rc);
        goto done;
    }
    r.scene = scene;
    for (int i = 0; i < scene->nnotes && root; i++) /* what import did with mesh files */
        fprintf(stderr, "clothsim: %s\n", scene->notes[i]);

    const char *format_name = o.format ? o.format : scene->output_format;
    if (!format_name)
        format_name = "ply";
    if (!cs_mesh_format_from_name(format_name, &r.format)) {
        if (root)
            fprintf(stderr, "clothsim: %s: output.format '%s' is not one of ply, obj, glb\n",
                scene->path, format_name);
        status = CS_EXIT_INPUT;
        goto done;
    }

    scene->def.plan_only = o.plan_only; /* --plan allocates nothing the step needs */
    rc = cs_sim_create_checked(&scene->def, &r.sim, err, sizeof err);
    if (rc != CS_OK) {
        if (root)
            fprintf(stderr, "clothsim: %s: %s\n", scene->path, err[0] ? err : "invalid scene");
        status = cs_exit_status(rc);
        goto done;
    }
    if (root && scene->def.dt > cs_sim_damped_dt(r.sim)) /* allowed: a sufficient bound */
        fprintf(stderr,
                "clothsim: warning: %s: time.dt %.3g s is %.3g times the stability limit "
                "%.3g s of the cloth at rest (damping included); it may still run, and a "
                "run that blows up stops with exit status 3\n",
                scene->path, scene->def.dt, scene->def.dt / cs_sim_damped_dt(r.sim),
                cs_sim_damped_dt(r.sim));
    if (o.plan_only) {
        if (root)
            cs_run_print_plan(scene, r.sim, stdout);
        status = CS_EXIT_OK;
        goto done;
    }

    /* The start's intersections and other problems (app/input_check.h):
     * an intersecting start is refused unless the scene accepts it. */
    if (!o.resume) {
        status = root ? cs_input_check_start(scene, o.quiet, stderr) : CS_EXIT_OK;
        if ((status = cs_sim_agree(r.sim, status)) != CS_EXIT_OK)
            goto done;
    }

    int ncloths = cs_sim_cloth_count(r.sim);
    r.views = calloc(ncloths > 0 ? (size_t)ncloths : 1, sizeof *r.views);
    if (cs_outdir_init(&r.out, o.out_dir, scene->name) != 0 || !r.views) {
        fprintf(stderr, "clothsim: out of memory\n");
        status = CS_EXIT_OUTPUT;
        goto done;
    }
    r.frames_dir = r.out.frames_dir;
    r.summary_path = r.out.summary_path;
    /* every rank: the same file gives the same outcome */
    if (cs_run_identity_init(&r.id, scene->path, o.noverrides, (const char *const *)o.overrides,
                             cs_mesh_format_extension(r.format), r.sim, scene, err,
                             sizeof err) != 0) {
        if (root)
            fprintf(stderr, "clothsim: %s\n", err);
        status = CS_EXIT_OUTPUT;
        goto done;
    }
    /* the folder's own scene.yaml: rewritten as the run goes, so only its
     * resolved scene can tell whether it is the run's */
    char *own = cs_outdir_scene(r.out.dir);
    struct stat a, b;
    r.id.own_scene = own && stat(own, &a) == 0 && stat(scene->path, &b) == 0 &&
                     a.st_dev == b.st_dev && a.st_ino == b.st_ino;
    free(own);
    cs_state_hash(r.sim, r.summary.initial_hash); /* frame 0's, before any resume */

    cs_summary *s = &r.summary;
    int triangles = 0;
    const char **names = calloc(ncloths > 0 ? (size_t)ncloths : 1, sizeof *names);
    for (int c = 0; names && c < ncloths; c++) {
        names[c] = cs_sim_cloth_name(r.sim, c);
        triangles += cs_sim_cloth_mesh(r.sim, c)->nt;
    }
    if (!names || cs_frame_layout_init(&r.out.layout, r.format, ncloths, names) != 0) {
        free(names);
        fprintf(stderr, "clothsim: out of memory\n");
        status = CS_EXIT_OUTPUT;
        goto done;
    }
    free(names);
    s->scene = scene->name;
    s->self_collision = scene->def.self_collision;
    for (int c = 0; c < scene->def.ncloths; c++)
        s->scripts = s->scripts || scene->def.cloths[c].nscripts > 0;
    s->script_zones =
        scene->def.self.script_zones == CS_SCRIPT_ZONES_HOLD ? "hold" : "follow";
    s->scene_file = scene->path;
    s->noverrides = o.noverrides;
    s->overrides = (const char *const *)o.overrides;
    s->version = CS_VERSION;
    s->format = cs_mesh_format_extension(r.format);
    s->output_dir = r.out.dir;
    s->frames_requested = scene->frames;
    s->fps = scene->def.fps;
    s->dt = cs_sim_dt(r.sim);
    if (!(scene->def.dt > 0))
        s->step_limit = cs_sim_step_limit(r.sim) == CS_STEP_DAMPED ? "damped" : "undamped";
    s->steps_per_frame = cs_run_steps_per_frame(scene->def.fps, s->dt);
    s->particles = cs_sim_particle_count(r.sim);
    s->springs = cs_sim_spring_count(r.sim);
    s->triangles = triangles;
    s->plan = *cs_sim_plan(r.sim);

    /* before the folder is cleared: a refused start loses no frames */
    if (o.start_from) {
        struct stat from_st, out_st;
        if (stat(o.start_from, &from_st) == 0 && stat(r.out.dir, &out_st) == 0 &&
            from_st.st_dev == out_st.st_dev && from_st.st_ino == out_st.st_ino) {
            snprintf(err, sizeof err, "--start-from %s: the run to start from is the output "
                     "folder, whose frames a new run removes: give another -o DIR",
                     o.start_from);
            status = CS_EXIT_INPUT;
        } else {
            status = root ? cs_start_from_open(o.start_from, scene, &r.origin, err, sizeof err)
                          : CS_EXIT_OK;
        }
        if (root && status != CS_EXIT_OK)
            fprintf(stderr, "clothsim: %s\n", err);
        if ((status = cs_sim_agree(r.sim, status)) != CS_EXIT_OK)
            goto done;
    }
    if (o.render && root) {
        r.render = cs_run_render_create(scene, r.sim, o.render, o.render_size, o.render_samples,
                                        r.out.dir, &status);
        if (!r.render)
            goto done;
    }
    status = cs_run_simulate(&r, &o);

done:
    cs_start_from_close(r.origin);
    cs_run_render_destroy(r.render);
    cs_summary_free(&r.summary);
    free(r.views);
    cs_run_identity_free(&r.id);
    cs_outdir_free(&r.out); /* the lock goes last */
    if (r.sim)
        cs_sim_destroy(r.sim);
    if (scene)
        cs_scene_destroy(scene);
    cs_run_free_options(&o);
    return status;
}
