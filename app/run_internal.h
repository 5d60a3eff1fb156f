/* run_internal.h: what the parts of `clothsim run` share: the command
 * line (run_options.c parses it), the state of a run (run.c sets it up,
 * run_loop.c simulates and writes its frames) and --plan (run_plan.c). */
#ifndef CS_APP_RUN_INTERNAL_H
#define CS_APP_RUN_INTERNAL_H

#include <stdbool.h>
#include <stdio.h>

#include "app/checkpoint.h"
#include "app/outdir.h"
#include "app/start_from.h"
#include "app/scene_render.h"
#include "app/summary.h"
#include "import/import.h"
#include "sim/sim.h"

#define ERRLEN 1024

typedef struct run_options {
    const char *scene_path;
    const char *out_dir;      /* NULL: out/<scene name> */
    const char *format;       /* NULL: the scene's output.format */
    int noverrides;
    char **overrides;         /* "KEY=VALUE", --frames last */
    char *frames_override;    /* owned "time.frames=N" */
    char *scene_in_dir;       /* owned DIR/scene.yaml when SCENE is a run folder */
    char *format_override;    /* owned "output.format=FMT" for --format: loaded
                                 last, so the resolved scene holds the format */
    bool plan_only;
    bool quiet;
    bool resume;              /* --resume: continue the run in DIR */
    const char *start_from;   /* --start-from RUN: begin where RUN ended */
    const char *render;       /* --render ENGINE, --size, --samples; NULL: none */
    const char *render_size, *render_samples;
    int threads;              /* --threads N; 0: one per core (see cs_parallel_set_threads) */
} run_options;

/* Returns -1 to go on, else an exit status. */
int cs_run_parse_options(int argc, char **argv, run_options *o);
void cs_run_free_options(run_options *o);

typedef struct run_state {
    const cs_scene *scene;
    cs_sim *sim;
    cs_mesh_format format;
    cs_outdir out;           /* the folder, its paths and its lock */
    const char *frames_dir;  /* out's, for the messages */
    const char *summary_path;
    cs_run_identity id;      /* what a resumed run must be made from */
    int first_frame;         /* frame 0, or the frame --resume continues after */
    double summary_at;       /* cs_now() of the last summary.json written */
    cs_mesh_view *views;     /* one per cloth */
    cs_run_render *render;   /* --render: an image per frame too */
    cs_start_from *origin;   /* --start-from: the run it begins from; NULL: none */
    cs_summary summary;
    double start;            /* cs_now() when the command began */
} run_state;

/* Rank 0 writes, prints and decides; the others simulate their particles
 * and follow its decision after every frame (cs_sim_agree), so a failed
 * write or an interrupt stops every rank at the same frame. */
int cs_run_simulate(run_state *r, const run_options *o);

/* Time steps in a frame of 1/fps s at step dt (0 without either). */
int cs_run_steps_per_frame(double fps, double dt);
/* Every row of the stage table in the order they run: the plan's numbered,
 * the others with what would bring them in. */
void cs_run_print_plan(const cs_scene *scene, const cs_sim *sim, FILE *out);

#endif
