/* run_plan.c: `clothsim run --plan`: the stages a time step will run, the
 * step size and the memory of the setup, printed without simulating. */
#include "app/run_internal.h"

#include "sim/sim.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>

int cs_run_steps_per_frame(double fps, double dt)
{
    if (!(fps > 0) || !(dt > 0))
        return 0;
    long n = lround(1.0 / fps / dt);   /* as cs_sim_advance_frame counts them */
    return n > 0 ? (int)n : 1;
}

void cs_run_print_plan(const cs_scene *scene, const cs_sim *sim, FILE *out)
{
    const cs_plan *plan = cs_sim_plan(sim);
    int width = 0;
    for (int i = 0; i < CS_STAGE_COUNT; i++) {
        int n = (int)strlen(cs_stage_name(cs_stage_in_order(i)));
        if (n > width)
            width = n;
    }
    fprintf(out, "plan of scene '%s' (%s): %d of %d stages\n", scene->name, scene->path,
            plan->nstages, CS_STAGE_COUNT);
    const char *when = NULL;
    for (int i = 0, number = 0; i < CS_STAGE_COUNT; i++) {
        cs_stage st = cs_stage_in_order(i);
        if (!when || strcmp(when, cs_stage_when(st)) != 0)
            fprintf(out, " %s:\n", when = cs_stage_when(st));
        if (cs_plan_has(plan, st))
            fprintf(out, "  %2d. %-*s  %s\n", ++number, width, cs_stage_name(st),
                    cs_stage_description(st));
        else
            fprintf(out, "   -  %-*s  left out: needs %s\n", width, cs_stage_name(st),
                    cs_stage_condition(st));
    }
    double dt = cs_sim_dt(sim);
    fprintf(out, "step size %.6g s (stability limit %.6g s): %d steps per frame at %g fps\n",
            dt, cs_sim_stable_dt(sim), cs_run_steps_per_frame(scene->def.fps, dt), scene->def.fps);
    fprintf(out, "  (limits at rest: undamped 2/omega_max %.6g s by Lanczos iterations, %.6g s "
            "by Gershgorin's bound; the damped scheme's %.6g s)\n", cs_sim_undamped_dt(sim),
            cs_sim_gershgorin_dt(sim), cs_sim_damped_dt(sim));
    if (!(scene->def.dt > 0)) {
        bool damped = cs_sim_step_limit(sim) == CS_STEP_DAMPED;
        fprintf(out, "  time.step_limit %s%s", scene->def.step_limit == CS_STEP_AUTO ? "auto: " : "",
                damped ? "damped" : "undamped");
        if (damped)
            fprintf(out, ": the step is chosen again before every outer step, smaller where "
                    "the cloth is stretched");
        double reach, cap = cs_sim_script_step_cap(sim, &reach);
        if (damped && isfinite(cap))
            fprintf(out, ",\n    and at most %.6g s in frame 1, so that no scripted vertex moves "
                    "more than %.3g mm a step", cap, 1e3 * reach);
        const char *why = cs_sim_step_limit_why(sim);
        if (why)
            fprintf(out, "\n    (the damped limit at rest is %.1f times the undamped one, "
                    "auto_min_gain %g; %s)", cs_sim_damped_dt(sim) / cs_sim_undamped_dt(sim),
                    scene->def.auto_min_gain, why);
        fputc('\n', out);
    }
    if (scene->def.self_collision && scene->def.self.pruning == CS_PRUNING_PATH)
        fprintf(out, "  self_collision.pruning path: step A keeps only the pairs whose straight "
                "relative paths come within the thickness\n");
    fprintf(out, "%d frames after the initial one: %.6g s of simulated time; %d particles\n",
            scene->frames, scene->def.fps > 0 ? scene->frames / scene->def.fps : 0.0,
            cs_sim_particle_count(sim));
    /* a plan holds the scene, the mesh, the bodies' level sets and the
     * springs; a run adds the step's scratch (plan_only leaves it out),
     * estimated per particle from the benchmark's measurements */
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0)
        return;
    double setup = ru.ru_maxrss * 1024.0, n = cs_sim_particle_count(sim);
    bool self = scene->def.self_collision;
    char at_setup[32], first[32], contact[32];
    cs_format_bytes(setup, at_setup, sizeof at_setup);
    cs_format_bytes(setup + cs_sim_estimate_bytes(n, self, false), first, sizeof first);
    cs_format_bytes(setup + cs_sim_estimate_bytes(n, self, true), contact, sizeof contact);
    fprintf(out, "memory: %s for the setup (this process, measured); a run needs about %s",
            at_setup, first);
    if (self)
        fprintf(out, " over its first frames and about %s once the cloth lies on itself "
                "(step A's pair lists grow with the contacts)", contact);
    fprintf(out, "\n  (estimates per particle from the benchmark drape, docs/performance.md)\n");
}
