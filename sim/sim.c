/* sim.c: the definitions' defaults, creating and destroying the
 * simulation, and its accessors. The stage table and the loops that run a
 * step and a frame are in stages.c, the stages' work in step.c and frame.c. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sim/internal.h"
#include "sim/stages.h"
#include "common/util.h"
#include "sim/vec3.h"

cs_cloth_material cs_default_cloth_material(void)
{
    cs_cloth_material m = {
        .edge_stiffness = 4.14,
        .edge_overdamping = 15,
        .bend_stiffness = 0.41,
        .bend_overdamping = 8,
        .node_mass = 1e-6,
        .density = 0,
    };
    return m;
}

cs_self_collision_def cs_default_self_collision_def(void)
{
    cs_self_collision_def d = {
        .thickness = 0.01,
        .stiffness = 30,
        .friction = 0.3,
        .edge_flip_epsilon = 0.5,
        .zone_iterations = 8,
        .scheme = CS_COLLISION_FIXED,
        .script_zones = CS_SCRIPT_ZONES_FOLLOW,
        .pruning = CS_PRUNING_SPEED,
        .verify = false,
    };
    return d;
}

cs_sim_def cs_default_sim_def(void)
{
    cs_sim_def d;
    memset(&d, 0, sizeof d);
    d.gravity[1] = -9.8;
    d.fps = 24;
    d.dt = 0;
    d.dt_safety = 0.5;
    d.step_limit = CS_STEP_AUTO;
    /* below 4x the damped step's per-step costs (a bound before every
     * outer step, tension that shrinks it in contact) eat its gain */
    d.auto_min_gain = 4;
    d.collision_steps = 16;
    d.cg_tolerance = 1e-3;
    d.cg_max_iterations = 1000;
    d.friction_method = CS_FRICTION_IMPROVED;
    d.bodies_enabled = true;
    d.wind_enabled = false;
    d.wind.ground_height = 1;
    d.wind.gust_length = 1;
    d.wind.gust_period = 2;
    d.self = cs_default_self_collision_def();
    d.comm = CS_COMM_WORLD;
    return d;
}

static int fail(char *err, size_t errlen, const char *fmt, ...)
{
    if (err && errlen) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, errlen, fmt, ap);
        va_end(ap);
    }
    return CS_ERR_INVALID;
}

static bool finite3(const double a[3])
{
    return isfinite(a[0]) && isfinite(a[1]) && isfinite(a[2]);
}

/* The core's own check, for programs that fill cs_sim_def themselves: a
 * scene file's values were checked already, with file and line, against
 * the ranges of import/scene_keys.def. tests/test_key_ranges.c holds these
 * checks to that table, so the two cannot drift apart. */
static int validate(const cs_sim_def *def, char *err, size_t errlen)
{
    if (def->ncloths < 1)
        return fail(err, errlen, "a scene needs at least one cloth");
    if (def->self_collision &&
        (!(def->self.thickness > 0) || !(def->self.stiffness >= 0) || !(def->self.friction >= 0) ||
         def->self.zone_iterations < 1))
        return fail(err, errlen, "self-collision needs thickness > 0, stiffness and friction "
                                 ">= 0, zone_iterations >= 1");
    if (def->self_collision &&
        !(def->self.edge_flip_epsilon >= -1 && def->self.edge_flip_epsilon <= 1))
        return fail(err, errlen, "self-collision needs edge_flip_epsilon in [-1, 1]");
    if (def->self.pruning != CS_PRUNING_SPEED && def->self.pruning != CS_PRUNING_PATH)
        return fail(err, errlen, "self-collision pruning must be speed or path");
    if (!(def->fps > 0))
        return fail(err, errlen, "fps must be > 0");
    if (!(def->dt >= 0) || !(def->dt_safety > 0 && def->dt_safety <= 1))
        return fail(err, errlen, "dt must be >= 0 and dt_safety in (0, 1]");
    if (def->step_limit != CS_STEP_UNDAMPED && def->step_limit != CS_STEP_DAMPED &&
        def->step_limit != CS_STEP_AUTO)
        return fail(err, errlen, "step_limit must be undamped, damped or auto");
    if (!(def->auto_min_gain >= 1))
        return fail(err, errlen, "auto_min_gain must be at least 1");
    if (def->collision_steps < 1 || !(def->cg_tolerance > 0) || def->cg_max_iterations < 1)
        return fail(err, errlen, "collision_steps, cg_tolerance and cg_max_iterations must be positive");
    if (!finite3(def->gravity))
        return fail(err, errlen, "gravity must be finite");
    if (!(def->wind.drag >= 0) || !finite3(def->wind.velocity) || !finite3(def->wind.ground_boost))
        return fail(err, errlen, "wind drag must be >= 0 and its velocities finite");
    if (!(def->wind.ground_height > 0) || !isfinite(def->wind.ground_height))
        return fail(err, errlen, "wind ground_height must be > 0 and finite");
    if (!(def->wind.gust >= 0) || !isfinite(def->wind.gust) || !(def->wind.gust_length > 0) ||
        !isfinite(def->wind.gust_length) || !(def->wind.gust_period > 0) ||
        !isfinite(def->wind.gust_period))
        return fail(err, errlen,
                    "wind gust must be >= 0, gust_length and gust_period > 0, all finite");
    for (int c = 0; c < def->ncloths; c++) {
        const cs_cloth_def *cl = def->cloths + c;
        const cs_cloth_material *m = &cl->material;
        if (!cl->mesh || cl->mesh->nv < 1)
            return fail(err, errlen, "cloth %d has no vertices", c);
        if (!(m->node_mass > 0) || !(m->density >= 0) || !(m->edge_stiffness >= 0) ||
            !(m->bend_stiffness >= 0) || !(m->edge_overdamping >= 0) || !(m->bend_overdamping >= 0))
            return fail(err, errlen, "cloth %d: mass must be > 0, stiffness and damping >= 0", c);
        for (int k = 0; k < 3 * cl->mesh->nv; k++)
            if (!isfinite(cl->mesh->x[k]))
                return fail(err, errlen, "cloth %d: vertex %d is not finite", c, k / 3);
        for (int k = 0; k < 3 * cl->mesh->nt; k++)
            if (cl->mesh->tri[k] < 0 || cl->mesh->tri[k] >= cl->mesh->nv)
                return fail(err, errlen, "cloth %d: triangle %d refers to a missing vertex", c, k / 3);
        for (int s = 0; s < cl->nscripts; s++)
            for (int k = 0; k < cl->scripts[s].nvertices; k++)
                if (cl->scripts[s].vertices[k] < 0 || cl->scripts[s].vertices[k] >= cl->mesh->nv)
                    return fail(err, errlen, "cloth %d: script %d selects a missing vertex", c, s);
        for (int s = 0; s < cl->nscripts; s++)
            if (!(cl->scripts[s].release_time >= 0 && isfinite(cl->scripts[s].release_time)))
                return fail(err, errlen, "cloth %d: script %d: release time must be finite and "
                                         ">= 0", c, s);
    }
    for (int b = 0; b < def->nbodies; b++) {
        const cs_body_def *body = def->bodies + b;
        if ((unsigned)body->shape >= CS_BODY_SHAPE_COUNT)
            return fail(err, errlen, "body %d: unknown shape", b);
        if (body->shape == CS_BODY_MESH && !body->phi_fn) /* never a silent plane */
            return fail(err, errlen, "body %d: a mesh body needs its level set", b);
        if (!(body->radius > 0))
            return fail(err, errlen, "body %d: radius must be > 0", b);
        if (!(body->friction >= 0))
            return fail(err, errlen, "body %d: friction must be >= 0", b);
        if (body->nfriction_keys < 0 || body->nfriction_keys > CS_BODY_MAX_FRICTION_KEYS)
            return fail(err, errlen, "body %d: %d friction keys (0 to %d)", b,
                        body->nfriction_keys, CS_BODY_MAX_FRICTION_KEYS);
        for (int k = 0; k < body->nfriction_keys; k++) {
            const cs_friction_key *fk = body->friction_keys + k;
            if (!(fk->friction >= 0) || !isfinite(fk->friction) || !isfinite(fk->time) ||
                (k > 0 && !(fk->time > fk[-1].time)))
                return fail(err, errlen, "body %d: friction key %d: friction must be finite and "
                                         ">= 0, times finite and strictly increasing", b, k);
        }
        if (!(body->offset >= 0 && isfinite(body->offset)))
            return fail(err, errlen, "body %d: collision offset must be finite and >= 0", b);
    }
    return CS_OK;
}

static int copy_motion(cs_motion *dst, const cs_motion *src)
{
    *dst = *src;
    dst->keys = NULL;
    if (src->kind == CS_MOTION_KEYFRAMES && src->nkeys > 0) {
        cs_keyframe *k = malloc(sizeof *k * (size_t)src->nkeys);
        if (!k)
            return -1;
        memcpy(k, src->keys, sizeof *k * (size_t)src->nkeys);
        dst->keys = k;
    } else {
        dst->nkeys = 0;
    }
    return 0;
}

static double *alloc3(int n) { return calloc((size_t)n * 3 + 3, sizeof(double)); }

/* Vertex masses: the node mass, or a third of the area of the adjacent
 * triangles times the areal density. */
static void cloth_masses(const cs_cloth_def *cl, double *mass)
{
    const cs_trimesh *m = cl->mesh;
    for (int i = 0; i < m->nv; i++)
        mass[i] = cl->material.density > 0 ? 0 : cl->material.node_mass;
    if (!(cl->material.density > 0))
        return;
    for (int t = 0; t < m->nt; t++) {
        const int *tri = m->tri + 3 * t;
        double e1[3], e2[3], c[3];
        cs_sub(m->x + 3 * tri[1], m->x + 3 * tri[0], e1);
        cs_sub(m->x + 3 * tri[2], m->x + 3 * tri[0], e2);
        cs_cross(e1, e2, c);
        double share = cl->material.density * 0.5 * cs_norm(c) / 3.0;
        for (int k = 0; k < 3; k++)
            mass[tri[k]] += share;
    }
    for (int i = 0; i < m->nv; i++) /* lone or degenerate vertices */
        if (!(mass[i] > 0))
            mass[i] = cl->material.node_mass;
}

cs_sim *cs_sim_create(const cs_sim_def *def, char *err, size_t errlen)
{
    cs_sim *sim = NULL;
    cs_sim_create_checked(def, &sim, err, errlen);
    return sim;
}

int cs_sim_create_checked(const cs_sim_def *def, cs_sim **out, char *err, size_t errlen)
{
    *out = NULL;
    if (validate(def, err, errlen) != CS_OK)
        return CS_ERR_INVALID;
    int status = CS_ERR_NOMEM;
    cs_sim *sim = calloc(1, sizeof *sim);
    if (!sim)
        return fail(err, errlen, "out of memory creating a simulation"), CS_ERR_NOMEM;
    sim->def = *def;
    sim->plan = cs_plan_from_def(def);
    sim->def.cloths = NULL;
    sim->def.bodies = NULL;

    int n = 0;
    for (int c = 0; c < def->ncloths; c++)
        n += def->cloths[c].mesh->nv;
    sim->n = n;
    sim->x = alloc3(n);
    sim->v = alloc3(n);
    sim->mass = calloc((size_t)n + 1, sizeof *sim->mass);
    sim->is_free = calloc((size_t)n + 1, 1);
    sim->mode = calloc((size_t)n + 1, 1);
    sim->cloths = calloc((size_t)def->ncloths, sizeof *sim->cloths);
    bool ok = sim->x && sim->v && sim->mass && sim->is_free && sim->mode && sim->cloths;
    if (ok && !def->plan_only) { /* the step's scratch */
        double **scratch[] = {&sim->x_prev, &sim->v_half, &sim->v_star, &sim->v_next,
                              &sim->force, &sim->v0, &sim->rhs, &sim->cg.z, &sim->cg.r,
                              &sim->cg.y, &sim->cg.p, &sim->cg.q,
                              &sim->cg.explicit_z, &sim->cg.warm_half, &sim->cg.warm_full_less_half,
                              &sim->cg.warm_half_before, &sim->cg.warm_full_less_half_before};
        for (size_t k = 0; k < sizeof scratch / sizeof *scratch && ok; k++)
            ok = (*scratch[k] = alloc3(n)) != NULL;
        ok = ok && (sim->cg.partial = calloc(3 * ((size_t)n / CS_BLOCK + 1), sizeof(double)));
        ok = ok && (sim->cg.block = calloc(6 * (size_t)n + 6, sizeof(double)));
        ok = ok && (sim->cg.inv_mass = calloc((size_t)n + 1, sizeof(double)));
    }
    if (!ok)
        goto nomem;

    /* particles, cloth by cloth */
    sim->ncloths = def->ncloths;
    int offset = 0;
    for (int c = 0; c < def->ncloths; c++) {
        const cs_cloth_def *cl = def->cloths + c;
        const cs_trimesh *m = cl->mesh;
        cs_cloth_state *cs = sim->cloths + c;
        cs->offset = offset;
        cs->name = strdup(cl->name ? cl->name : "cloth");
        cs->mesh = cs_trimesh_create(m->nv, m->nt);
        if (!cs->name || !cs->mesh)
            goto nomem;
        memcpy(cs->mesh->x, m->x, sizeof *m->x * 3 * (size_t)m->nv);
        memcpy(cs->mesh->tri, m->tri, sizeof *m->tri * 3 * (size_t)m->nt);
        memcpy(sim->x + 3 * offset, m->x, sizeof *m->x * 3 * (size_t)m->nv);
        cloth_masses(cl, sim->mass + offset);
        for (int i = 0; i < m->nv; i++) {
            memcpy(sim->v + 3 * (offset + i), cl->velocity, 3 * sizeof(double));
            sim->is_free[offset + i] = 1;
            if (sim->cg.inv_mass) /* not with plan_only */
                sim->cg.inv_mass[offset + i] = 1.0 / sim->mass[offset + i];
        }
        /* springs hold global particle indices into x and mass */
        if (cs_springs_add_mesh(&sim->springs, offset, m->nv, m->nt, m->tri, sim->x, sim->mass,
                                cl->material.edge_stiffness, cl->material.edge_overdamping,
                                cl->material.bend_stiffness, cl->material.bend_overdamping))
            goto nomem;
        sim->nscripts += cl->nscripts;
        offset += m->nv;
    }

    /* pinned and scripted vertices */
    if (sim->nscripts > 0) {
        sim->scripts = calloc((size_t)sim->nscripts, sizeof *sim->scripts);
        sim->script_x = alloc3(n);
        sim->script_v = alloc3(n);
        sim->script_of = malloc(sizeof *sim->script_of * ((size_t)n + 1));
        sim->script_lag = calloc((size_t)sim->nscripts, sizeof *sim->script_lag);
        sim->script_lag_start = calloc((size_t)sim->nscripts, sizeof *sim->script_lag_start);
        if (!sim->scripts || !sim->script_x || !sim->script_v || !sim->script_of ||
            !sim->script_lag || !sim->script_lag_start)
            goto nomem;
        for (int i = 0; i < n; i++)
            sim->script_of[i] = -1;
        sim->stage_bytes[CS_STAGE_SCRIPTED_VERTICES] +=
            (2 * 3 * sizeof(double) + sizeof(int)) * (size_t)n +
            2 * sizeof(double) * (size_t)sim->nscripts;
        int s = 0;
        for (int c = 0; c < def->ncloths; c++) {
            const cs_cloth_def *cl = def->cloths + c;
            for (int k = 0; k < cl->nscripts; k++, s++) {
                const cs_vertex_script *src = cl->scripts + k;
                cs_script_state *dst = sim->scripts + s;
                if (copy_motion(&dst->motion, &src->motion))
                    goto nomem;
                double c0[3];
                cs_motion_pose(&dst->motion, 0.0, dst->rotation0, c0, NULL, NULL);
                dst->nvertices = src->nvertices;
                dst->release_time = src->release_time;
                dst->vertices = malloc(sizeof *dst->vertices * (size_t)(src->nvertices + 1));
                dst->local = alloc3(src->nvertices);
                if (!dst->vertices || !dst->local)
                    goto nomem;
                sim->stage_bytes[CS_STAGE_SCRIPTED_VERTICES] +=
                    (sizeof(int) + 3 * sizeof(double)) * (size_t)src->nvertices;
                for (int j = 0; j < src->nvertices; j++) {
                    int g = sim->cloths[c].offset + src->vertices[j];
                    double rel[3];
                    dst->vertices[j] = g;
                    sim->script_of[g] = s;
                    cs_sub(sim->x + 3 * g, c0, rel);
                    cs_mat_apply_transpose(dst->rotation0, rel, dst->local + 3 * j);
                    dst->radius = fmax(dst->radius, cs_norm(dst->local + 3 * j));
                    sim->is_free[g] = 0;
                }
            }
        }
    }

    /* bodies, and the arrays only their stages use */
    sim->nbodies = def->nbodies;
    if (def->nbodies > 0) {
        sim->bodies = calloc((size_t)def->nbodies, sizeof *sim->bodies);
        if (!sim->bodies)
            goto nomem;
        for (int b = 0; b < def->nbodies; b++) {
            sim->bodies[b] = def->bodies[b];
            sim->bodies[b].name = NULL; /* names stay with the caller */
            if (copy_motion(&sim->bodies[b].motion, &def->bodies[b].motion))
                goto nomem;
        }
    }
    if (cs_plan_has(&sim->plan, CS_STAGE_BODY_COLLISION) && !def->plan_only) {
        sim->contact_normal = alloc3(n);
        sim->contact_body = calloc((size_t)n + 1, sizeof *sim->contact_body);
        sim->body_pose = calloc((size_t)def->nbodies + 1, sizeof *sim->body_pose);
        if (!sim->contact_normal || !sim->contact_body || !sim->body_pose)
            goto nomem;
        sim->stage_bytes[CS_STAGE_BODY_COLLISION] = (3 * sizeof(double) + sizeof(int)) * (size_t)n +
                                                     sizeof(cs_body_pose) * (size_t)def->nbodies;
    }
    if (cs_plan_has(&sim->plan, CS_STAGE_WIND) && !def->plan_only) {
        sim->wind_normal = alloc3(n);
        sim->wind_area = calloc((size_t)n + 1, sizeof *sim->wind_area);
        if (!sim->wind_normal || !sim->wind_area)
            goto nomem;
        sim->stage_bytes[CS_STAGE_WIND] = 4 * sizeof(double) * (size_t)n;
    }

    if (cs_plan_has(&sim->plan, CS_STAGE_COLLISIONS) && !def->plan_only) {
        sim->selfcol = cs_selfcol_create(sim);
        if (!sim->selfcol)
            goto nomem;
        sim->stage_bytes[CS_STAGE_COLLISIONS] = sim->selfcol->bytes;
        if (def->self.scheme == CS_COLLISION_REWIND) {
            sim->v_rewind = alloc3(n);
            if (!sim->v_rewind)
                goto nomem;
            sim->stage_bytes[CS_STAGE_COLLISIONS] += 3 * sizeof(double) * (size_t)n;
        }
    }

    /* time step: the stability limits at the rest state (step_limit.c),
     * from all springs on every rank (before the partition keeps its own);
     * with the damped limit, advance_frame chooses the step again from the
     * tension before each outer step. The undamped limit holds for the
     * whole run: it is computed with the vertices that scripts will let go
     * already free (by Cauchy interlacing, held vertices, which remove rows
     * and columns, can only lower the largest eigenvalue). */
    cs_scripts_hold_releasable(sim, false);
    cs_step_limit_init(sim);
    cs_scripts_hold_releasable(sim, true);
    double frame = 1.0 / def->fps;
    double dt_max = def->dt > 0 ? def->dt : def->dt_safety * sim->stable_dt;
    if (!(def->dt > 0) && sim->step_limit == CS_STEP_DAMPED)
        dt_max = fmin(dt_max, cs_step_limit_scripts(sim, sim->t, sim->t + frame));
    if (dt_max > frame)
        dt_max = frame;
    double steps = ceil(frame / dt_max - 1e-9); /* a double: 1/fps over 1e-308 fits */
    if (!(steps <= CS_MAX_STEPS_PER_FRAME)) {
        if (def->dt > 0)
            fail(err, errlen,
                 "time.dt is too small: %.3g s makes a frame of %.3g s %.3g steps (at most "
                 "%d)", def->dt, frame, steps, CS_MAX_STEPS_PER_FRAME);
        else
            fail(err, errlen,
                 "the stability limit of the cloths' springs is %.3g s, so a frame of %.3g s "
                 "would need %.3g steps (at most %d); check the cloths' stiffness and mass",
                 sim->stable_dt, frame, steps, CS_MAX_STEPS_PER_FRAME);
        goto invalid;
    }
    sim->dt = frame / (steps >= 1 ? steps : 1);
    cs_runaway_init(sim); /* from all springs and particles, like the step */
    if (def->plan_only) { /* the step size is all a plan needs */
        *out = sim;
        return CS_OK;
    }

    sim->nsprings = sim->springs.n;
    /* Section 7: owners and ghosts; each rank keeps the springs it needs */
    sim->par = cs_par_create(def->comm, n, sim->x, sim->springs.n, sim->springs.ends);
    sim->active = calloc((size_t)n + 1, 1);
    sim->rank_comm = calloc((size_t)(sim->par ? sim->par->size : 1) + 1, sizeof *sim->rank_comm);
    if (!sim->par || !sim->active || !sim->rank_comm)
        goto nomem;
    cs_springs_keep_touching(&sim->springs, sim->par->owner, sim->par->rank);
    if (cs_springs_index(&sim->springs, sim->par->nowned, cs_par_owned(sim->par), n) ||
        cs_shares_init(&sim->shares, sim->par->nowned, CS_BLOCK))
        goto nomem;
    sim->springs.shares = &sim->shares; /* its rows are the owned particles too */
    if (sim->selfcol && cs_selfcol_set_ranks(sim) != 0)
        goto nomem;
    for (int i = 0; i < n; i++)
        sim->active[i] = sim->is_free[i] && cs_par_owns(sim->par, i);
    *out = sim;
    return CS_OK;

nomem:
    fail(err, errlen, "out of memory creating a simulation of %d particles", n);
    goto failed;
invalid:
    status = CS_ERR_INVALID;
failed:
    cs_sim_destroy(sim);
    return status;
}

void cs_sim_destroy(cs_sim *sim)
{
    if (!sim)
        return;
    for (int c = 0; c < sim->ncloths && sim->cloths; c++) {
        free(sim->cloths[c].name);
        cs_trimesh_destroy(sim->cloths[c].mesh);
    }
    free(sim->cloths);
    for (int s = 0; s < sim->nscripts && sim->scripts; s++) {
        free((void *)sim->scripts[s].motion.keys);
        free(sim->scripts[s].vertices);
        free(sim->scripts[s].local);
    }
    free(sim->scripts);
    for (int b = 0; b < sim->nbodies && sim->bodies; b++)
        free((void *)sim->bodies[b].motion.keys);
    free(sim->bodies);
    cs_springs_free(&sim->springs);
    cs_shares_free(&sim->shares);
    cs_selfcol_destroy(sim->selfcol);
    cs_par_destroy(sim->par);
    free(sim->active);
    free(sim->rank_comm);
    double *arrays[] = {sim->x, sim->v, sim->mass, sim->x_prev, sim->v_half, sim->v_star,
                        sim->v_next, sim->force, sim->v0, sim->rhs, sim->script_x,
                        sim->script_v, sim->contact_normal, sim->wind_normal, sim->wind_area, sim->v_rewind,
                        sim->cg.z, sim->cg.r, sim->cg.y, sim->cg.p, sim->cg.q,
                        sim->cg.partial, sim->cg.explicit_z, sim->cg.warm_half,
                        sim->cg.warm_full_less_half, sim->cg.warm_half_before, sim->cg.warm_full_less_half_before,
                        sim->cg.block, sim->cg.inv_mass};
    for (size_t k = 0; k < sizeof arrays / sizeof *arrays; k++)
        free(arrays[k]);
    free(sim->is_free);
    free(sim->mode);
    free(sim->bound_rows);
    free(sim->bound_value);
    free(sim->script_of);
    free(sim->script_lag);
    free(sim->script_lag_start);
    free(sim->contact_body);
    free(sim->body_pose);
    free(sim);
}

double cs_sim_time(const cs_sim *sim) { return sim->t; }
double cs_sim_dt(const cs_sim *sim) { return sim->dt; }
double cs_sim_stable_dt(const cs_sim *sim) { return sim->stable_dt; }
double cs_sim_undamped_dt(const cs_sim *sim) { return sim->undamped_dt; }
double cs_sim_damped_dt(const cs_sim *sim) { return sim->damped_dt; }
cs_step_limit cs_sim_step_limit(const cs_sim *sim) { return sim->step_limit; }
const char *cs_sim_step_limit_why(const cs_sim *sim) { return sim->step_limit_why; }
double cs_sim_script_step_cap(const cs_sim *sim, double *reach)
{
    if (reach)
        *reach = sim->script_reach;
    return cs_step_limit_scripts(sim, 0.0, 1.0 / sim->def.fps);
}
double cs_sim_gershgorin_dt(const cs_sim *sim) { return sim->gershgorin_dt; }
int cs_sim_particle_count(const cs_sim *sim) { return sim->n; }
int cs_sim_spring_count(const cs_sim *sim) { return sim->nsprings; }
const double *cs_sim_positions(const cs_sim *sim) { return sim->x; }
const double *cs_sim_velocities(const cs_sim *sim) { return sim->v; }
const double *cs_sim_masses(const cs_sim *sim) { return sim->mass; }
int cs_sim_cloth_count(const cs_sim *sim) { return sim->ncloths; }
int cs_sim_cloth_offset(const cs_sim *sim, int c) { return sim->cloths[c].offset; }
const cs_trimesh *cs_sim_cloth_mesh(const cs_sim *sim, int c) { return sim->cloths[c].mesh; }
const char *cs_sim_cloth_name(const cs_sim *sim, int c) { return sim->cloths[c].name; }
const cs_plan *cs_sim_plan(const cs_sim *sim) { return &sim->plan; }
const cs_stage_timing *cs_sim_stage_timing(const cs_sim *sim)
{
    return sim->par->size > 1 ? sim->timing_all : sim->timing;
}
const cs_comm_stats *cs_sim_stage_comm(const cs_sim *sim)
{
    return sim->par->size > 1 ? sim->comm_all : sim->par->stats;
}
/* here, not in runaway.c: the stage's name is the stage table's, which
 * lies above the checks */
bool cs_sim_runaway(const cs_sim *sim, const char **stage, double *speed, double *limit)
{
    if (sim->runaway.stage < 0)
        return false;
    if (stage)
        *stage = cs_stage_name((cs_stage)sim->runaway.stage);
    if (speed)
        *speed = sim->runaway.speed;
    if (limit)
        *limit = sim->runaway.limit;
    return true;
}
int cs_sim_agree(cs_sim *sim, int value) { return cs_par_bcast_int(sim->par, value); }
int cs_sim_rank(const cs_sim *sim) { return sim->par->rank; }
int cs_sim_ranks(const cs_sim *sim) { return sim->par->size; }
const cs_comm_stats *cs_sim_rank_comm(const cs_sim *sim) { return sim->rank_comm; }
size_t cs_sim_stage_bytes(const cs_sim *sim, cs_stage stage)
{
    return (unsigned)stage < CS_STAGE_COUNT ? sim->stage_bytes[stage] : 0;
}
