/* sim.c: creating the simulation and the semi-implicit Newmark step of
 * Section 3 (B.1, B.3-B.7), timed stage by stage. Self-collision steps
 * (A, B.2, B.8, C) plug in around these in the outer collision loop. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sim/internal.h"
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
    d.collision_steps = 16;
    d.cg_tolerance = 1e-3;
    d.cg_max_iterations = 1000;
    d.friction_method = CS_FRICTION_IMPROVED;
    d.bodies_enabled = true;
    d.wind_enabled = false;
    d.self = cs_default_self_collision_def();
    d.comm = CS_COMM_WORLD;
    return d;
}

#define STAGE_BEGIN(sim, stage)                                        \
    double stage_t0_##stage = cs_now();                                \
    cs_par_begin((sim)->par, stage)
#define STAGE_END(sim, stage)                                          \
    do {                                                               \
        (sim)->timing[stage].seconds += cs_now() - stage_t0_##stage;   \
        (sim)->timing[stage].calls++;                                  \
    } while (0)

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

static int validate(const cs_sim_def *def, char *err, size_t errlen)
{
    if (def->ncloths < 1)
        return fail(err, errlen, "a scene needs at least one cloth");
    if (def->self_collision &&
        (!(def->self.thickness > 0) || !(def->self.stiffness >= 0) || !(def->self.friction >= 0) ||
         def->self.zone_iterations < 1))
        return fail(err, errlen, "self-collision needs thickness > 0, stiffness and friction "
                                 ">= 0, zone_iterations >= 1");
    if (!(def->fps > 0))
        return fail(err, errlen, "fps must be > 0");
    if (!(def->dt >= 0) || !(def->dt_safety > 0 && def->dt_safety <= 1))
        return fail(err, errlen, "dt must be >= 0 and dt_safety in (0, 1]");
    if (def->step_limit != CS_STEP_UNDAMPED && def->step_limit != CS_STEP_DAMPED)
        return fail(err, errlen, "step_limit must be undamped or damped");
    if (def->collision_steps < 1 || !(def->cg_tolerance > 0) || def->cg_max_iterations < 1)
        return fail(err, errlen, "collision_steps, cg_tolerance and cg_max_iterations must be positive");
    if (!finite3(def->gravity))
        return fail(err, errlen, "gravity must be finite");
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
    }
    for (int b = 0; b < def->nbodies; b++) {
        const cs_body_def *body = def->bodies + b;
        if ((unsigned)body->shape >= CS_BODY_SHAPE_COUNT)
            return fail(err, errlen, "body %d: unknown shape", b);
        if (body->shape == CS_BODY_MESH && !body->phi_fn) /* never a silent plane */
            return fail(err, errlen, "body %d: a mesh body needs its level set", b);
        if (!(body->friction >= 0))
            return fail(err, errlen, "body %d: friction must be >= 0", b);
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
                              &sim->cg.y, &sim->cg.p, &sim->cg.q, &sim->cg.b,
                              &sim->cg.explicit_z, &sim->cg.warm_half, &sim->cg.warm_full};
        for (size_t k = 0; k < sizeof scratch / sizeof *scratch && ok; k++)
            ok = (*scratch[k] = alloc3(n)) != NULL;
        ok = ok && (sim->cg.partial = calloc(2 * ((size_t)n / CS_BLOCK + 1), sizeof(double)));
        ok = ok && (sim->cg.block = calloc(6 * (size_t)n + 6, sizeof(double)));
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
        if (!sim->scripts || !sim->script_x || !sim->script_v)
            goto nomem;
        sim->stage_bytes[CS_STAGE_SCRIPTED_VERTICES] += 2 * 3 * sizeof(double) * (size_t)n;
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
                    cs_sub(sim->x + 3 * g, c0, rel);
                    cs_mat_apply_transpose(dst->rotation0, rel, dst->local + 3 * j);
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
        if (!sim->contact_normal || !sim->contact_body)
            goto nomem;
        sim->stage_bytes[CS_STAGE_BODY_COLLISION] = (3 * sizeof(double) + sizeof(int)) * (size_t)n;
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
     * tension before each outer step */
    cs_step_limit_init(sim);
    double frame = 1.0 / def->fps;
    double dt_max = def->dt > 0 ? def->dt : def->dt_safety * sim->stable_dt;
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
    if (cs_springs_index(&sim->springs, sim->par->nowned, cs_par_owned(sim->par), n))
        goto nomem;
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
    cs_selfcol_destroy(sim->selfcol);
    cs_par_destroy(sim->par);
    free(sim->active);
    free(sim->rank_comm);
    double *arrays[] = {sim->x, sim->v, sim->mass, sim->x_prev, sim->v_half, sim->v_star,
                        sim->v_next, sim->force, sim->v0, sim->rhs, sim->script_x,
                        sim->script_v, sim->contact_normal, sim->wind_normal, sim->wind_area, sim->v_rewind,
                        sim->cg.z, sim->cg.r, sim->cg.y, sim->cg.p, sim->cg.q,
                        sim->cg.b, sim->cg.partial, sim->cg.explicit_z, sim->cg.warm_half,
                        sim->cg.warm_full, sim->cg.block};
    for (size_t k = 0; k < sizeof arrays / sizeof *arrays; k++)
        free(arrays[k]);
    free(sim->is_free);
    free(sim->mode);
    free(sim->contact_body);
    free(sim);
}

/* Targets of scripted vertices at time t: position and velocity. */
static void script_targets(cs_sim *sim, double t)
{
    for (int s = 0; s < sim->nscripts; s++) {
        cs_script_state *sc = sim->scripts + s;
        double R[9], c[3], vel[3], w[3];
        cs_motion_pose(&sc->motion, t, R, c, vel, w);
        for (int j = 0; j < sc->nvertices; j++) {
            int g = sc->vertices[j];
            double r[3], wr[3];
            cs_mat_apply(R, sc->local + 3 * j, r);
            cs_cross(w, r, wr);
            for (int d = 0; d < 3; d++) {
                sim->script_x[3 * g + d] = c[d] + r[d];
                sim->script_v[3 * g + d] = vel[d] + wr[d];
            }
        }
    }
}

/* Area-weighted vertex normals and a third of the adjacent area. */
static void wind_geometry(cs_sim *sim, const double *x)
{
    memset(sim->wind_normal, 0, sizeof(double) * 3 * (size_t)sim->n);
    memset(sim->wind_area, 0, sizeof(double) * (size_t)sim->n);
    for (int c = 0; c < sim->ncloths; c++) {
        const cs_trimesh *m = sim->cloths[c].mesh;
        int off = sim->cloths[c].offset;
        for (int t = 0; t < m->nt; t++) {
            int a = off + m->tri[3 * t], b = off + m->tri[3 * t + 1], cc = off + m->tri[3 * t + 2];
            double e1[3], e2[3], cr[3];
            cs_sub(x + 3 * b, x + 3 * a, e1);
            cs_sub(x + 3 * cc, x + 3 * a, e2);
            cs_cross(e1, e2, cr); /* |cr| = twice the area */
            int v[3] = {a, b, cc};
            for (int k = 0; k < 3; k++) {
                cs_axpy(1.0, cr, sim->wind_normal + 3 * v[k]);
                sim->wind_area[v[k]] += cs_norm(cr) / 6.0;
            }
        }
    }
    for (int i = 0; i < sim->n; i++) {
        double *nrm = sim->wind_normal + 3 * i, l = cs_norm(nrm);
        if (l > 0)
            for (int d = 0; d < 3; d++)
                nrm[d] /= l;
    }
}

/* force = elastic(x) + m g + explicit wind part, for owned particles (the
 * springs also add into ghosts, which nobody reads) */
static void explicit_forces(cs_sim *sim, const double *x)
{
    CS_FOR_LOCAL(sim->par, i)
        sim->force[3 * i] = sim->force[3 * i + 1] = sim->force[3 * i + 2] = 0;
    cs_springs_add_elastic(&sim->springs, x, sim->force);
    CS_FOR_OWNED(sim->par, i)
        cs_axpy(sim->mass[i], sim->def.gravity, sim->force + 3 * i);
    if (sim->wind_normal) {
        double c = sim->def.wind.drag;
        CS_FOR_OWNED(sim->par, i) {
            const double *nrm = sim->wind_normal + 3 * i;
            cs_axpy(c * sim->wind_area[i] * cs_dot(nrm, sim->def.wind.velocity), nrm,
                    sim->force + 3 * i);
        }
    }
}

/* rhs = M v_start + h force */
static void momentum_rhs(cs_sim *sim, const double *v_start)
{
    CS_FOR_OWNED(sim->par, i)
        for (int d = 0; d < 3; d++)
            sim->rhs[3 * i + d] = sim->mass[i] * v_start[3 * i + d] + sim->h * sim->force[3 * i + d];
}

/* Copies 3 doubles per particle over the given ranges. */
static void copy_ranges(const int *ranges, int nranges, double *dst, const double *src)
{
    for (int r = 0; r < nranges; r++)
        memcpy(dst + 3 * ranges[2 * r], src + 3 * ranges[2 * r],
               sizeof(double) * 3 * (size_t)(ranges[2 * r + 1] - ranges[2 * r]));
}

/* The improved method applies B.5's forces without the contact
 * projection, so that B.7 sees the normal force. Where that force pulls a
 * contact particle off the body, nothing in B.5 damped the pull (the
 * projection held the normal velocity), and at steps far above the
 * undamped limit the explicit pull grows without bound. Such a particle
 * leaves the body: it takes the projected solve's velocity, as the
 * previous method would give it, and B.4 stops holding it next step. */
static void release_separating(cs_sim *sim, int i, double t1, const double *v_p)
{
    int b = sim->contact_body[i];
    if (b < 0)
        return;
    double vb[3], rel[3];
    cs_body_def_velocity(sim->bodies + b, t1, sim->x + 3 * i, vb);
    cs_sub(sim->v_next + 3 * i, vb, rel);
    if (cs_dot(rel, sim->contact_normal + 3 * i) <= 0)
        return;
    for (int d = 0; d < 3; d++)
        sim->v_next[3 * i + d] = 2.0 * v_p[3 * i + d] - sim->v_star[3 * i + d];
}

/* True on every rank when every owned particle is finite everywhere. */
int cs_sim_step(cs_sim *sim, double dt)
{
    cs_par *par = sim->par;
    const cs_plan *plan = &sim->plan;
    bool bodies = cs_plan_has(plan, CS_STAGE_BODY_COLLISION);
    double t1 = sim->t + dt;
    if (fabs(t1 - sim->frame_end) <= 1e-9 * dt)
        t1 = sim->frame_end;
    sim->h = 0.5 * dt;
    /* x (owned and ghosts) is current here; v only where owned */
    copy_ranges(par->local, par->nlocal, sim->x_prev, sim->x);
    CS_FOR_OWNED(par, i)
        sim->mode[i] = sim->is_free[i] ? CS_FREE : CS_FIXED;
    cs_runaway_begin_step(sim, t1);

    if (sim->nscripts > 0) {
        STAGE_BEGIN(sim, CS_STAGE_SCRIPTED_VERTICES);
        script_targets(sim, t1);
        STAGE_END(sim, CS_STAGE_SCRIPTED_VERTICES);
    }
    if (sim->wind_normal) {
        STAGE_BEGIN(sim, CS_STAGE_WIND);
        wind_geometry(sim, sim->x);
        STAGE_END(sim, CS_STAGE_WIND);
    }

    /* B.1: v~^(n+1/2) = v^n + dt/2 a(x^n, v~^(n+1/2)), unconstrained by
     * contact (constraining it would make cloth stick to bodies). Scripted
     * particles move straight to their targets. */
    STAGE_BEGIN(sim, CS_STAGE_VELOCITY_HALF);
    copy_ranges(par->own, par->nown, sim->v0, sim->v);
    CS_FOR_OWNED(par, i)
        if (!sim->is_free[i])
            for (int d = 0; d < 3; d++)
                sim->v0[3 * i + d] = (sim->script_x[3 * i + d] - sim->x[3 * i + d]) / dt;
    explicit_forces(sim, sim->x); /* prepares the springs' directions at x^n too */
    momentum_rhs(sim, sim->v);
    sim->cg_iterations += cs_cg_solve(sim, sim->v0, sim->rhs, sim->v_half, sim->cg.warm_half);
    cs_runaway_check(sim, sim->v_half, CS_STAGE_VELOCITY_HALF);
    STAGE_END(sim, CS_STAGE_VELOCITY_HALF);

    /* B.2: repulsions change only the velocity that moves the positions */
    if (sim->selfcol) {
        STAGE_BEGIN(sim, CS_STAGE_SELF_REPULSION);
        cs_selfcol_repulse(sim, sim->x, sim->v_half, dt, true);
        cs_runaway_check(sim, sim->v_half, CS_STAGE_SELF_REPULSION);
        STAGE_END(sim, CS_STAGE_SELF_REPULSION);
    }

    /* B.3 */
    STAGE_BEGIN(sim, CS_STAGE_POSITION_UPDATE);
    CS_FOR_OWNED(par, i) {
        if (sim->is_free[i]) {
            for (int d = 0; d < 3; d++)
                sim->x[3 * i + d] = sim->x_prev[3 * i + d] + dt * sim->v_half[3 * i + d];
        } else { /* exact targets, free of round-off */
            memcpy(sim->x + 3 * i, sim->script_x + 3 * i, 3 * sizeof(double));
        }
    }
    STAGE_END(sim, CS_STAGE_POSITION_UPDATE);

    /* B.4 */
    if (bodies) {
        STAGE_BEGIN(sim, CS_STAGE_BODY_COLLISION);
        cs_body_collide(sim, dt);
        cs_runaway_check(sim, sim->v_star, CS_STAGE_BODY_COLLISION);
        STAGE_END(sim, CS_STAGE_BODY_COLLISION);
    } else {
        copy_ranges(par->own, par->nown, sim->v_star, sim->v);
    }
    { /* the ghosts' new positions, for the forces at x^(n+1/2): B.3's messages */
        double t0 = cs_now();
        cs_par_begin(par, CS_STAGE_POSITION_UPDATE);
        cs_halo_forward(par, &par->ghosts, sim->x, 3);
        sim->timing[CS_STAGE_POSITION_UPDATE].seconds += cs_now() - t0;
    }

    /* B.5 and B.6: v^(n+1/2) = v*^n + dt/2 a(x^(n+1/2), v^(n+1/2)) with the
     * normal velocity of contact particles held (P), then
     * v^(n+1) = 2 v^(n+1/2) - v*^n. The improved method extrapolates from
     * v_NP: the same forces, damping evaluated at the projected solution,
     * applied without projection, so B.7 sees the normal force. */
    STAGE_BEGIN(sim, CS_STAGE_VELOCITY_FULL);
    CS_FOR_OWNED(par, i)
        if (!sim->is_free[i])
            memcpy(sim->v_star + 3 * i, sim->v0 + 3 * i, 3 * sizeof(double));
    CS_FOR_LOCAL(par, i) /* x^(n+1/2), reusing v_half */
        for (int d = 0; d < 3; d++)
            sim->v_half[3 * i + d] = 0.5 * (sim->x_prev[3 * i + d] + sim->x[3 * i + d]);
    explicit_forces(sim, sim->v_half); /* and at x^(n+1/2) */
    momentum_rhs(sim, sim->v_star);
    double *v_p = sim->v0; /* v0 is free again */
    copy_ranges(par->own, par->nown, sim->cg.b, sim->v_star);
    sim->cg_iterations += cs_cg_solve(sim, sim->cg.b, sim->rhs, v_p, sim->cg.warm_full);
    if (bodies && sim->def.friction_method == CS_FRICTION_IMPROVED) {
        copy_ranges(par->local, par->nlocal, sim->v_next, sim->force);
        cs_halo_forward(par, &par->ghosts, v_p, 3);
        cs_damping_apply(sim, v_p, sim->v_next); /* F_i + F_d v_P */
        CS_FOR_OWNED(par, i) {
            for (int d = 0; d < 3; d++) {
                int k = 3 * i + d;
                double v_np = sim->v_star[k] + sim->h / sim->mass[i] * sim->v_next[k];
                sim->v_next[k] = 2.0 * v_np - sim->v_star[k];
            }
            release_separating(sim, i, t1, v_p);
        }
    } else {
        CS_FOR_OWNED(par, i)
            for (int d = 0; d < 3; d++)
                sim->v_next[3 * i + d] = 2.0 * v_p[3 * i + d] - sim->v_star[3 * i + d];
    }
    CS_FOR_OWNED(par, i)
        if (!sim->is_free[i])
            memcpy(sim->v_next + 3 * i, sim->script_v + 3 * i, 3 * sizeof(double));
    cs_runaway_check(sim, sim->v_next, CS_STAGE_VELOCITY_FULL);
    STAGE_END(sim, CS_STAGE_VELOCITY_FULL);

    /* B.7 */
    if (bodies) {
        STAGE_BEGIN(sim, CS_STAGE_BODY_FRICTION);
        cs_body_friction(sim, dt);
        cs_runaway_check(sim, sim->v_next, CS_STAGE_BODY_FRICTION);
        STAGE_END(sim, CS_STAGE_BODY_FRICTION);
    }
    /* B.8: inelastic repulsion and friction on the final velocity */
    if (sim->selfcol) {
        STAGE_BEGIN(sim, CS_STAGE_SELF_FRICTION);
        cs_selfcol_repulse(sim, sim->x, sim->v_next, dt, false);
        cs_runaway_check(sim, sim->v_next, CS_STAGE_SELF_FRICTION);
        STAGE_END(sim, CS_STAGE_SELF_FRICTION);
    }
    copy_ranges(par->own, par->nown, sim->v, sim->v_next);
    sim->t = t1;
    return cs_runaway_end_step(sim) ? CS_OK : CS_ERR_UNSTABLE;
}

/* One outer collision step of k time steps (Section 4): step A, k steps of
 * B, step C. The rewind scheme (Bridson et al. 2002) first runs the k steps
 * and, if step C would find a collision, goes back and tries again with k
 * halved, until k = 1. Returns CS_OK or CS_ERR_UNSTABLE. */
static int outer_step(cs_sim *sim, int k)
{
    cs_selfcol *sc = sim->selfcol;
    if (!sc) {
        for (int i = 0; i < k; i++)
            if (cs_sim_step(sim, sim->dt) != CS_OK)
                return CS_ERR_UNSTABLE;
        return CS_OK;
    }
    bool rewind = sim->def.self.scheme == CS_COLLISION_REWIND;
    size_t bytes = sizeof(double) * 3 * (size_t)sim->n;
    double t0 = sim->t;
    if (rewind) /* keep the start to come back to; x equals x_free here */
        memcpy(sim->v_rewind, sim->v, bytes);
    for (;;) {
        STAGE_BEGIN(sim, CS_STAGE_REPULSION_PAIRS);
        cs_selfcol_find_pairs(sim, k * sim->dt);
        STAGE_END(sim, CS_STAGE_REPULSION_PAIRS);
        for (int i = 0; i < k; i++)
            if (cs_sim_step(sim, sim->dt) != CS_OK)
                return CS_ERR_UNSTABLE;
        if (rewind && k > 1) {
            STAGE_BEGIN(sim, CS_STAGE_COLLISIONS);
            long found = cs_selfcol_collide(sim, sim->t - t0, k, true);
            STAGE_END(sim, CS_STAGE_COLLISIONS);
            if (found > 0) {
                memcpy(sim->x, sc->x_free, bytes);
                memcpy(sim->v, sim->v_rewind, bytes);
                sim->t = t0;
                sc->stats.rewinds++;
                /* the halves run one after another, each from its own start */
                int first = k / 2, status = outer_step(sim, first);
                if (status != CS_OK)
                    return status;
                return outer_step(sim, k - first);
            }
        }
        STAGE_BEGIN(sim, CS_STAGE_COLLISIONS);
        cs_selfcol_collide(sim, sim->t - t0, k, false);
        cs_runaway_check(sim, sim->v, CS_STAGE_COLLISIONS);
        STAGE_END(sim, CS_STAGE_COLLISIONS);
        return cs_runaway_end_step(sim) ? CS_OK : CS_ERR_UNSTABLE;
    }
}

static bool adaptive_step(const cs_sim *sim)
{
    return !(sim->def.dt > 0) && sim->def.step_limit == CS_STEP_DAMPED;
}

/* The step for the rest of a frame: the frame's remaining time in equal
 * steps no longer than dt_safety times the stability limit at the current
 * positions (or the scene's fixed step). Returns the number of steps. */
static long steps_for(cs_sim *sim, double remaining)
{
    if (!adaptive_step(sim)) /* fixed: the step set at creation */
        return lround(remaining / sim->dt);
    double dt_max = sim->def.dt_safety * cs_step_limit_now(sim);
    double steps = ceil(remaining / fmin(dt_max, remaining) - 1e-9);
    if (!(steps >= 1))
        steps = 1;
    if (steps > CS_MAX_STEPS_PER_FRAME)
        steps = CS_MAX_STEPS_PER_FRAME;
    sim->dt = remaining / steps;
    return (long)steps;
}

int cs_sim_advance_frame(cs_sim *sim, cs_frame_stats *stats)
{
    double frame = 1.0 / sim->def.fps;
    double t_end = sim->t + frame;
    sim->frame_end = t_end;
    long steps = 0;
    long cg0 = sim->cg_iterations, contacts0 = sim->contacts;
    cs_selfcol_stats self0 = {0};
    if (sim->selfcol) {
        sim->selfcol->stats.max_zone = 0; /* the largest zone of this frame */
        self0 = sim->selfcol->stats;
    }
    int status = CS_OK;
    /* The outer collision loop: k_i time steps, then step C. Chunks never
     * straddle a frame end, so every frame ends collision-free. The step is
     * chosen afresh before each chunk, from the tension the cloth has then
     * (step_limit.c); the steps left divide the frame's remaining time. */
    bool adaptive = adaptive_step(sim);
    /* the last step lands on t_end (cs_sim_step), free of the steps'
     * round-off */
    long left = steps_for(sim, frame);
    while (left > 0 && status == CS_OK) {
        long chunk = left < sim->def.collision_steps ? left : sim->def.collision_steps;
        status = outer_step(sim, (int)chunk);
        steps += chunk;
        left -= chunk;
        if (left > 0 && adaptive && status == CS_OK)
            left = steps_for(sim, t_end - sim->t);
    }
    /* rank 0 gets the whole state: frames are written once */
    cs_par_begin(sim->par, CS_STAGE_POSITION_UPDATE);
    cs_par_gather_root(sim->par, sim->x, 3);
    cs_par_gather_root(sim->par, sim->v, 3);
    long intersections = -1;
    if (status == CS_OK && cs_plan_has(&sim->plan, CS_STAGE_VERIFY)) {
        STAGE_BEGIN(sim, CS_STAGE_VERIFY);
        if (sim->par->rank == 0)
            intersections = cs_sim_count_intersections(sim);
        STAGE_END(sim, CS_STAGE_VERIFY);
    }
    /* counters each rank kept for its own particles and pairs */
    cs_selfcol_stats self = {0};
    if (sim->selfcol)
        self = sim->selfcol->stats;
    long sums[4] = {sim->contacts - contacts0, self.repulsion_pairs - self0.repulsion_pairs,
                    self.repulsions - self0.repulsions, self.collisions - self0.collisions};
    cs_par_begin(sim->par, CS_STAGE_VELOCITY_FULL);
    cs_par_sum_long(sim->par, sums, 4);
    double max_speed = 0;
    CS_FOR_OWNED(sim->par, i)
        max_speed = fmax(max_speed, cs_norm(sim->v + 3 * i));
    cs_par_max(sim->par, &max_speed, 1);
    cs_par_report(sim->par, sim->timing, sim->timing_all, sim->comm_all, sim->rank_comm);
    if (stats) {
        memset(stats, 0, sizeof *stats);
        stats->steps = (int)steps;
        stats->dt = frame / (double)steps; /* the mean step */
        stats->cg_iterations = sim->cg_iterations - cg0;
        stats->body_contacts = sums[0];
        stats->max_speed = max_speed;
        if (sim->selfcol) { /* passes, zones and rewinds are the same on every rank */
            stats->repulsion_pairs = sums[1];
            stats->repulsions = sums[2];
            stats->collisions = sums[3];
            stats->collision_passes = self.passes - self0.passes;
            stats->impact_zones = self.zones - self0.zones;
            stats->max_zone_size = self.max_zone;
            stats->rewinds = self.rewinds - self0.rewinds;
        }
        stats->intersections = intersections;
    }
    return status;
}

long cs_sim_count_intersections(const cs_sim *sim)
{
    /* every cloth's triangles in global particle indices, as one mesh */
    long nt = 0;
    for (int c = 0; c < sim->ncloths; c++)
        nt += sim->cloths[c].mesh->nt;
    int *tri = malloc(sizeof *tri * 3 * (size_t)(nt + 1));
    if (!tri)
        return -1;
    long t = 0;
    for (int c = 0; c < sim->ncloths; c++) {
        const cs_trimesh *m = sim->cloths[c].mesh;
        for (int k = 0; k < 3 * m->nt; k++)
            tri[3 * t + k] = sim->cloths[c].offset + m->tri[k];
        t += m->nt;
    }
    long count = cs_count_intersections(sim->n, sim->x, (int)nt, tri);
    free(tri);
    return count;
}

double cs_sim_time(const cs_sim *sim) { return sim->t; }
double cs_sim_dt(const cs_sim *sim) { return sim->dt; }
double cs_sim_stable_dt(const cs_sim *sim) { return sim->stable_dt; }
double cs_sim_undamped_dt(const cs_sim *sim) { return sim->undamped_dt; }
double cs_sim_damped_dt(const cs_sim *sim) { return sim->damped_dt; }
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
int cs_sim_agree(cs_sim *sim, int value) { return cs_par_bcast_int(sim->par, value); }
int cs_sim_rank(const cs_sim *sim) { return sim->par->rank; }
int cs_sim_ranks(const cs_sim *sim) { return sim->par->size; }
const cs_comm_stats *cs_sim_rank_comm(const cs_sim *sim) { return sim->rank_comm; }
size_t cs_sim_stage_bytes(const cs_sim *sim, cs_stage stage)
{
    return (unsigned)stage < CS_STAGE_COUNT ? sim->stage_bytes[stage] : 0;
}
