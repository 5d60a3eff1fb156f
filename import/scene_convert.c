/* scene_convert.c: the raw structs libcyaml filled -> a cs_scene.
 *
 * Every value is checked once, against the range its key has in
 * scene_keys.def, and an absent one gets the default from there
 * (scene_values.c); keys the table converts TO a field go through
 * cs_sl_convert_keys, the others through the code of their section (time,
 * camera and bodies here; cloths: scene_cloth.c; meshes and mesh bodies:
 * scene_mesh.c).
 */
#include "import/scene_internal.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* --------------------------------------------------------------- bodies */

/* A key that the body's shape does not use is a mistake, not a no-op. */
static int unused(loader *L, const void *given, const char *base, const char *key, int shape)
{
    char p[PATH_LEN];
    if (!given)
        return CS_OK;
    snprintf(p, sizeof p, "%s.%s", base, key);
    return cs_sl_fail(L, p, false, "is not used by a %s (remove it)",
                      cs_scene_enum_name(CS_SKEY(body, shape), shape));
}

static int required(loader *L, const void *given, const char *base, const char *key, int shape)
{
    char p[PATH_LEN];
    if (given)
        return CS_OK;
    snprintf(p, sizeof p, "%s.%s", base, key);
    return cs_sl_fail(L, p, false, "is required for a %s",
                      cs_scene_enum_name(CS_SKEY(body, shape), shape));
}

static const char *body_name(const cs_scene *s, int j)
{
    return s->def.bodies[j].name;
}

/* The friction schedule: instead of a constant friction, keys in strictly
 * increasing time with friction >= 0 (held by value in the definition). */
_Static_assert(CS_BODY_MAX_FRICTION_KEYS == 16,
               "scene_keys.def's bodies[].friction_keys says at most 16 keys");
static int convert_friction_keys(loader *L, const cs_raw_body *rb, const char *base,
                                 cs_body_def *bd)
{
    char p[PATH_LEN];
    int err;
    bd->nfriction_keys = 0;
    if (!rb->friction_keys)
        return CS_OK;
    snprintf(p, sizeof p, "%s.friction_keys", base);
    if (rb->friction)
        return cs_sl_fail(L, p, false, "expected either friction or friction_keys (got both)");
    if (rb->friction_keys_count > CS_BODY_MAX_FRICTION_KEYS)
        return cs_sl_fail(L, p, false, "must have at most %d keys (got %u)",
                          CS_BODY_MAX_FRICTION_KEYS, rb->friction_keys_count);
    for (unsigned k = 0; k < rb->friction_keys_count; k++) {
        const cs_raw_friction_key *rk = &rb->friction_keys[k];
        if (k > 0 && !(rk->time > rb->friction_keys[k - 1].time)) {
            snprintf(p, sizeof p, "%s.friction_keys[%u].time", base, k);
            return cs_sl_fail(L, p, true, "must be greater than the previous key's time %g",
                              rb->friction_keys[k - 1].time);
        }
        char key[96];
        snprintf(key, sizeof key, "%s.friction_keys[%u]", base, k);
        if ((err = cs_sl_num(L, CS_SKEY(friction_key, friction), &rk->friction, key,
                             &bd->friction_keys[k].friction)))
            return err;
        bd->friction_keys[k].time = rk->time;
    }
    bd->nfriction_keys = (int)rb->friction_keys_count;
    return CS_OK;
}

static int convert_body(loader *L, const cs_raw_body *rb, int bi, cs_scene *s)
{
    cs_body_def *bd = (cs_body_def *)&s->def.bodies[bi];
    char base[48], p[PATH_LEN];
    double pos[3], q[4];
    int err, shape = rb->shape;

    *bd = cs_default_body_def();
    bd->name = NULL;
    memset(&bd->motion, 0, sizeof bd->motion);
    snprintf(base, sizeof base, "bodies[%d]", bi);
    char *name = NULL;
    err = cs_sl_entry_name(L, rb->name, "bodies", "body", bi, body_name, s, &name);
    bd->name = name;
    if (err)
        return err;
    bd->shape = (cs_body_shape)shape;

    if ((err = cs_sl_vec(L, CS_SKEY(body, position), rb->position, base, NULL, pos)))
        return err;
    if (rb->normal) {
        double n[3], len;
        if ((err = unused(L, shape == CS_BODY_PLANE ? NULL : rb->normal, base, "normal", shape)))
            return err;
        snprintf(p, sizeof p, "%s.normal", base);
        if (rb->rotation)
            return cs_sl_fail(L, p, false, "expected either normal or rotation (got both)");
        len = sqrt(rb->normal[0] * rb->normal[0] + rb->normal[1] * rb->normal[1] +
                   rb->normal[2] * rb->normal[2]);
        if (!(len > 0) || !isfinite(len))
            return cs_sl_fail(L, p, false, "must be a nonzero vector");
        for (int k = 0; k < 3; k++)
            n[k] = rb->normal[k] / len;
        cs_quat_from_y_to(n, q);
    } else {
        double deg[3];
        if ((err = cs_sl_vec(L, CS_SKEY(body, rotation), rb->rotation, base, NULL, deg)))
            return err;
        cs_quat_from_euler_degrees(deg, q);
    }

    bool radius = shape == CS_BODY_SPHERE || shape == CS_BODY_CYLINDER;
    bool size = shape == CS_BODY_BOX, height = shape == CS_BODY_CYLINDER;
    if ((err = (radius ? required : unused)(L, rb->radius, base, "radius", shape)) ||
        (err = (size ? required : unused)(L, rb->size, base, "size", shape)) ||
        (err = (height ? required : unused)(L, rb->height, base, "height", shape)))
        return err;
    bool mesh = shape == CS_BODY_MESH;
    if ((err = (mesh ? required : unused)(L, rb->mesh, base, "mesh", shape)) ||
        (err = unused(L, mesh ? NULL : rb->voxel_size, base, "voxel_size", shape)) ||
        (err = unused(L, mesh ? NULL : rb->band, base, "band", shape)) ||
        (err = unused(L, mesh ? NULL : rb->close_holes, base, "close_holes", shape)) ||
        (err = unused(L, mesh ? NULL : rb->interior, base, "interior", shape)))
        return err;
    if (mesh && (err = cs_sl_convert_mesh_body(L, rb, bi, s)))
        return err;
    if ((err = cs_sl_convert_keys(L, CS_SEC_body, rb, base, bd)) ||
        (err = convert_friction_keys(L, rb, base, bd)))
        return err;
    if (rb->size) {
        if ((err = cs_sl_vec(L, CS_SKEY(body, size), rb->size, base, NULL, bd->half_extents)))
            return err;
        for (int k = 0; k < 3; k++)
            bd->half_extents[k] *= 0.5;
    }
    if (rb->height) {
        if ((err = cs_sl_num(L, CS_SKEY(body, height), rb->height, base, &bd->half_height)))
            return err;
        bd->half_height *= 0.5;
    }
    if ((err = cs_sl_vec(L, CS_SKEY(body, color), rb->color, base, NULL, s->body_colors + 3 * bi)))
        return err;
    snprintf(p, sizeof p, "%s.motion", base);
    return cs_sl_convert_motion(L, rb->motion, p, pos, q, &bd->motion);
}

/* ---------------------------------------------------------------- scene */

static int convert_time(loader *L, const cs_raw_time *t, cs_scene *s)
{
    int rc = cs_sl_convert_keys(L, CS_SEC_time, t, "time", s);
    if (rc || !t || !t->dt)
        return rc;
    /* A string in the schema so that "auto" loads; read the number here. */
    char *end;
    double dt = 0;
    if (strcmp(t->dt, "auto") != 0) {
        const cs_key_range *range = &CS_SKEY(time, dt)->range;
        char text[64];
        cs_key_range_text(range, text, sizeof text);
        dt = strtod(t->dt, &end);
        if (!*t->dt || isspace((unsigned char)*t->dt) || *end || !isfinite(dt) ||
            !cs_key_in_range(range, dt))
            return cs_sl_fail(L, "time.dt", true, "expected a number %s or auto", text);
    }
    s->def.dt = dt;
    return CS_OK;
}

static int convert_camera(loader *L, const cs_raw_camera *c, cs_camera_def *cam)
{
    memset(cam, 0, sizeof *cam);
    int rc = cs_sl_convert_keys(L, CS_SEC_camera, c, "camera", cam);
    cam->given = c != NULL;
    if (rc || !c)
        return rc;
    double dir[3], cross[3];
    for (int k = 0; k < 3; k++)
        dir[k] = cam->target[k] - cam->position[k];
    if (dir[0] == 0 && dir[1] == 0 && dir[2] == 0)
        return cs_sl_fail(L, "camera.target", false, "must differ from camera.position");
    cross[0] = cam->up[1] * dir[2] - cam->up[2] * dir[1];
    cross[1] = cam->up[2] * dir[0] - cam->up[0] * dir[2];
    cross[2] = cam->up[0] * dir[1] - cam->up[1] * dir[0];
    double lc = sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]);
    double lu = sqrt(cam->up[0] * cam->up[0] + cam->up[1] * cam->up[1] + cam->up[2] * cam->up[2]);
    double ld = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    if (!(lc > 1e-9 * lu * ld))
        return cs_sl_fail(L, "camera.up", false,
                          "must be nonzero and not along the view direction (target - position)");
    return cs_sl_convert_motion(L, c->motion, "camera.motion", cam->target,
                                (const double[4]){1, 0, 0, 0}, &cam->motion);
}

/* "dir/name.yaml" -> "name". */
static char *file_stem(const char *file)
{
    const char *base = strrchr(file, '/');
    base = base ? base + 1 : file;
    const char *dot = strrchr(base, '.');
    size_t n = dot && dot != base ? (size_t)(dot - base) : strlen(base);
    char *stem = malloc(n + 1);
    if (stem) {
        memcpy(stem, base, n);
        stem[n] = '\0';
    }
    return stem;
}

int cs_sl_convert_scene(loader *L, const cs_raw_scene *r, const char *default_name, cs_scene **out)
{
    int rc;
    cs_scene *s = calloc(1, sizeof *s);
    *out = NULL;
    if (!s)
        return CS_ERR_NOMEM;
    s->def = cs_default_sim_def();
    s->def.cloths = NULL;
    s->def.ncloths = 0;
    s->def.bodies = NULL;
    s->def.nbodies = 0;

    if ((rc = cs_sl_check_name(L, r->name, "name")))
        goto fail;
    s->name = r->name        ? cs_sl_strdup(r->name)
              : default_name ? cs_sl_strdup(default_name)
                             : file_stem(L->file);
    s->path = cs_sl_strdup(L->file);
    if (!s->name || !s->path)
        goto nomem;

    if ((rc = convert_time(L, r->time, s)) ||
        (rc = cs_sl_vec(L, CS_SKEY(scene, gravity), r->gravity, "", NULL, s->def.gravity)) ||
        (rc = cs_sl_convert_keys(L, CS_SEC_effects, r->effects, "effects", &s->def)) ||
        (rc = cs_sl_convert_keys(L, CS_SEC_check, r->check, "check", s)) ||
        (rc = cs_sl_convert_keys(L, CS_SEC_output, r->output, "output", s)))
        goto fail;
    bool wind_effect =
        r->effects && r->effects->wind ? *r->effects->wind : CS_SKEY(effects, wind)->def(0) != 0;
    L->self_collision = s->def.self_collision;
    if ((rc = cs_sl_convert_keys(L, CS_SEC_self, r->self_collision, "self_collision",
                                 &s->def.self)) ||
        (rc = cs_sl_convert_keys(L, CS_SEC_wind, r->wind, "wind", &s->def.wind)))
        goto fail;
    s->def.wind_enabled = r->wind && wind_effect && s->def.wind.drag > 0;

    const cs_scene_key *format = CS_SKEY(output, format);
    s->output_format = cs_sl_strdup(cs_scene_enum_name(
        format, r->output && r->output->format ? *r->output->format : (int)format->def(0)));
    if (!s->output_format)
        goto nomem;
    if ((rc = convert_camera(L, r->camera, &s->camera)))
        goto fail;

    /* Arrays are zeroed first so that a partly filled scene frees cleanly. */
    s->cloth_colors = calloc(3 * (size_t)r->cloths_count, sizeof *s->cloth_colors);
    s->def.cloths = calloc(r->cloths_count, sizeof *s->def.cloths);
    if (!s->cloth_colors || !s->def.cloths)
        goto nomem;
    s->def.ncloths = (int)r->cloths_count;
    for (unsigned c = 0; c < r->cloths_count; c++)
        if ((rc = cs_sl_convert_cloth(L, &r->cloths[c], (int)c, s)))
            goto fail;

    if (r->bodies_count > 0) {
        s->body_colors = calloc(3 * (size_t)r->bodies_count, sizeof *s->body_colors);
        s->def.bodies = calloc(r->bodies_count, sizeof *s->def.bodies);
        s->mesh_bodies = calloc(r->bodies_count, sizeof *s->mesh_bodies);
        if (!s->body_colors || !s->def.bodies || !s->mesh_bodies)
            goto nomem;
        s->def.nbodies = (int)r->bodies_count;
        for (unsigned b = 0; b < r->bodies_count; b++)
            if ((rc = convert_body(L, &r->bodies[b], (int)b, s)))
                goto fail;
        if ((rc = cs_sl_finish_mesh_bodies(L, s)))
            goto fail;
    }
    if (r->levelset && r->levelset->cache && !*r->levelset->cache) {
        rc = cs_sl_fail(L, "levelset.cache", false, "must not be empty (none turns the cache off)");
        goto fail;
    }
    char *dir = cs_sl_scene_dir(L->file);
    if (!dir)
        goto nomem;
    s->levelset_cache = cs_levelset_cache_dir(r->levelset ? r->levelset->cache : NULL, dir);
    free(dir);
    *out = s;
    return CS_OK;
nomem:
    rc = CS_ERR_NOMEM;
fail:
    cs_scene_destroy(s);
    return rc;
}

void cs_scene_destroy(cs_scene *s)
{
    if (!s)
        return;
    for (int c = 0; s->def.cloths && c < s->def.ncloths; c++) {
        cs_cloth_def *cd = (cs_cloth_def *)&s->def.cloths[c];
        free((void *)cd->name);
        if (cd->mesh)
            cs_trimesh_destroy((cs_trimesh *)cd->mesh);
        for (int i = 0; cd->scripts && i < cd->nscripts; i++) {
            free((void *)cd->scripts[i].vertices);
            free((void *)cd->scripts[i].motion.keys);
        }
        free((void *)cd->scripts);
    }
    free((void *)s->def.cloths);
    for (int b = 0; s->def.bodies && b < s->def.nbodies; b++) {
        free((void *)s->def.bodies[b].name);
        free((void *)s->def.bodies[b].motion.keys);
    }
    free((void *)s->def.bodies);
    free((void *)s->camera.motion.keys);
    for (int b = 0; s->mesh_bodies && b < s->def.nbodies; b++) {
        cs_scene_mesh_body *mb = &s->mesh_bodies[b];
        if (mb->sign_mesh != mb->mesh)
            cs_trimesh_destroy(mb->sign_mesh);
        cs_trimesh_destroy(mb->mesh);
        cs_levelset_destroy(mb->levelset);
        free(mb->file);
        free(mb->cache_path);
    }
    free(s->mesh_bodies);
    free(s->levelset_cache);
    for (int i = 0; i < s->nassets; i++) {
        free(s->assets[i].source);
        free(s->assets[i].name);
    }
    free(s->assets);
    free(s->resolved);
    free(s->resolved_setup);
    for (int i = 0; i < s->nnotes; i++)
        free(s->notes[i]);
    free(s->notes);
    free(s->name);
    free(s->path);
    free(s->output_format);
    free(s->cloth_colors);
    free(s->body_colors);
    free(s);
}
