/* scene_schema.c: the libcyaml schema of a scene file and queries on it.
 * README.md (Scene file reference) describes the same keys for users; keep the two
 * in step. */
#include "import/scene_schema.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "import/import.h"
#include "sim/sim.h"

/* Every optional key: absent leaves the member NULL. */
#define OPT (CYAML_FLAG_POINTER | CYAML_FLAG_OPTIONAL)
#define REQ CYAML_FLAG_POINTER

static const cyaml_schema_value_t float_value = {
    CYAML_VALUE_FLOAT(CYAML_FLAG_DEFAULT, double),
};
static const cyaml_schema_value_t int_value = {
    CYAML_VALUE_INT(CYAML_FLAG_DEFAULT, int),
};
static const cyaml_schema_value_t vec3_value = {
    CYAML_VALUE_SEQUENCE_FIXED(CYAML_FLAG_DEFAULT, double, &float_value, 3),
};
static const cyaml_schema_value_t int3_value = {
    CYAML_VALUE_SEQUENCE_FIXED(CYAML_FLAG_DEFAULT, int, &int_value, 3),
};
static const cyaml_schema_value_t int2_value = {
    CYAML_VALUE_SEQUENCE_FIXED(CYAML_FLAG_DEFAULT, int, &int_value, 2),
};

#define VEC(key, flags, type, member, n) \
    CYAML_FIELD_SEQUENCE_FIXED(key, flags, type, member, &float_value, n)
#define NUM(key, type, member) CYAML_FIELD_FLOAT_PTR(key, OPT, type, member)
#define INT(key, type, member) CYAML_FIELD_INT_PTR(key, OPT, type, member)
#define BOOL(key, type, member) CYAML_FIELD_BOOL_PTR(key, OPT, type, member)
#define STR(key, type, member) \
    CYAML_FIELD_STRING_PTR(key, OPT, type, member, 0, CYAML_UNLIMITED)

static const cyaml_strval_t friction_names[] = {
    {"improved", CS_FRICTION_IMPROVED},
    {"projection", CS_FRICTION_PROJECTION},
};

const char *const cs_scene_format_names[] = {"ply", "obj", "glb"};
static const cyaml_strval_t format_names[] = {{"ply", 0}, {"obj", 1}, {"glb", 2}};

static const cyaml_strval_t shape_names[] = {
    {"plane", CS_BODY_PLANE},
    {"sphere", CS_BODY_SPHERE},
    {"box", CS_BODY_BOX},
    {"cylinder", CS_BODY_CYLINDER},
    {"mesh", CS_BODY_MESH},
};

const char *const cs_scene_unit_names[CS_SCENE_UNIT_COUNT] = {"auto", "m",  "cm", "mm",
                                                              "km",   "in", "ft"};
static const cyaml_strval_t interior_names[] = {
    {"auto", CS_INTERIOR_AUTO}, {"fill", CS_INTERIOR_FILL}, {"band", CS_INTERIOR_BAND}};
static const cyaml_strval_t unit_names[] = {{"auto", 0}, {"m", 1},  {"cm", 2}, {"mm", 3},
                                            {"km", 4},   {"in", 5}, {"ft", 6}};

static const cyaml_schema_field_t time_fields[] = {
    NUM("fps", cs_raw_time, fps),
    INT("frames", cs_raw_time, frames),
    STR("dt", cs_raw_time, dt),
    NUM("dt_safety", cs_raw_time, dt_safety),
    INT("collision_steps", cs_raw_time, collision_steps),
    NUM("cg_tolerance", cs_raw_time, cg_tolerance),
    INT("cg_max_iterations", cs_raw_time, cg_max_iterations),
    CYAML_FIELD_END,
};
/* dt is a string in the schema only so that "auto" passes; say so. */
#define DT_VALUE (&time_fields[2].value)

static const cyaml_schema_field_t effects_fields[] = {
    BOOL("bodies", cs_raw_effects, bodies),
    BOOL("wind", cs_raw_effects, wind),
    BOOL("self_collision", cs_raw_effects, self_collision),
    CYAML_FIELD_ENUM_PTR("friction", OPT | CYAML_FLAG_STRICT, cs_raw_effects, friction,
                         friction_names, CYAML_ARRAY_LEN(friction_names)),
    CYAML_FIELD_END,
};

static const cyaml_strval_t scheme_names[] = {
    {"fixed", CS_COLLISION_FIXED},
    {"rewind", CS_COLLISION_REWIND},
};

static const cyaml_schema_field_t self_fields[] = {
    NUM("thickness", cs_raw_self, thickness),
    NUM("stiffness", cs_raw_self, stiffness),
    NUM("friction", cs_raw_self, friction),
    NUM("edge_flip_epsilon", cs_raw_self, edge_flip_epsilon),
    INT("zone_iterations", cs_raw_self, zone_iterations),
    CYAML_FIELD_ENUM_PTR("scheme", OPT | CYAML_FLAG_STRICT, cs_raw_self, scheme, scheme_names,
                         CYAML_ARRAY_LEN(scheme_names)),
    BOOL("verify", cs_raw_self, verify),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t wind_fields[] = {
    VEC("velocity", OPT, cs_raw_wind, velocity, 3),
    NUM("drag", cs_raw_wind, drag),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t output_fields[] = {
    CYAML_FIELD_ENUM_PTR("format", OPT | CYAML_FLAG_STRICT, cs_raw_output, format,
                         format_names, CYAML_ARRAY_LEN(format_names)),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t camera_fields[] = {
    VEC("position", REQ, cs_raw_camera, position, 3),
    VEC("target", REQ, cs_raw_camera, target, 3),
    VEC("up", OPT, cs_raw_camera, up, 3),
    NUM("fov", cs_raw_camera, fov),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t grid_fields[] = {
    VEC("size", OPT, cs_raw_grid, size, 2),
    CYAML_FIELD_SEQUENCE_FIXED("resolution", OPT, cs_raw_grid, resolution, &int_value, 2),
    VEC("center", OPT, cs_raw_grid, center, 3),
    VEC("rotation", OPT, cs_raw_grid, rotation, 3),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t mesh_fields[] = {
    STR("file", cs_raw_mesh, file),
    STR("node", cs_raw_mesh, node),
    CYAML_FIELD_ENUM_PTR("units", OPT | CYAML_FLAG_STRICT, cs_raw_mesh, units, unit_names,
                         CYAML_ARRAY_LEN(unit_names)),
    CYAML_FIELD_IGNORE("scale", CYAML_FLAG_OPTIONAL),
    CYAML_FIELD_SEQUENCE("vertices", OPT, cs_raw_mesh, vertices, &vec3_value, 1,
                         CYAML_UNLIMITED),
    CYAML_FIELD_SEQUENCE("triangles", OPT, cs_raw_mesh, triangles, &int3_value, 0,
                         CYAML_UNLIMITED),
    VEC("rotation", OPT, cs_raw_mesh, rotation, 3),
    VEC("translate", OPT, cs_raw_mesh, translate, 3),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t material_fields[] = {
    NUM("edge_stiffness", cs_raw_material, edge_stiffness),
    NUM("edge_overdamping", cs_raw_material, edge_overdamping),
    NUM("bend_stiffness", cs_raw_material, bend_stiffness),
    NUM("bend_overdamping", cs_raw_material, bend_overdamping),
    NUM("node_mass", cs_raw_material, node_mass),
    NUM("density", cs_raw_material, density),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t box_fields[] = {
    VEC("min", REQ, cs_raw_box, min, 3),
    VEC("max", REQ, cs_raw_box, max, 3),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t selection_fields[] = {
    CYAML_FIELD_SEQUENCE("vertices", OPT, cs_raw_selection, vertices, &int_value, 1,
                         CYAML_UNLIMITED),
    CYAML_FIELD_MAPPING_PTR("box", OPT, cs_raw_selection, box, box_fields),
    CYAML_FIELD_SEQUENCE("grid_points", OPT, cs_raw_selection, grid_points, &int2_value, 1,
                         CYAML_UNLIMITED),
    CYAML_FIELD_END,
};
static const cyaml_schema_value_t selection_value = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_DEFAULT, cs_raw_selection, selection_fields),
};

static const cyaml_schema_field_t key_fields[] = {
    CYAML_FIELD_FLOAT("time", CYAML_FLAG_DEFAULT, cs_raw_key, time),
    VEC("translate", OPT, cs_raw_key, translate, 3),
    VEC("rotate", OPT, cs_raw_key, rotate, 3),
    CYAML_FIELD_END,
};
static const cyaml_schema_value_t key_value = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_DEFAULT, cs_raw_key, key_fields),
};

static const cyaml_schema_field_t motion_fields[] = {
    VEC("velocity", OPT, cs_raw_motion, velocity, 3),
    VEC("angular_velocity", OPT, cs_raw_motion, angular_velocity, 3),
    CYAML_FIELD_SEQUENCE("keys", OPT, cs_raw_motion, keys, &key_value, 1, CYAML_UNLIMITED),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t script_fields[] = {
    CYAML_FIELD_MAPPING_PTR("select", REQ, cs_raw_script, select, selection_fields),
    VEC("pivot", OPT, cs_raw_script, pivot, 3),
    CYAML_FIELD_MAPPING_PTR("motion", OPT, cs_raw_script, motion, motion_fields),
    CYAML_FIELD_END,
};
static const cyaml_schema_value_t script_value = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_DEFAULT, cs_raw_script, script_fields),
};

static const cyaml_schema_field_t cloth_fields[] = {
    STR("name", cs_raw_cloth, name),
    VEC("color", OPT, cs_raw_cloth, color, 3),
    CYAML_FIELD_MAPPING_PTR("grid", OPT, cs_raw_cloth, grid, grid_fields),
    CYAML_FIELD_MAPPING_PTR("mesh", OPT, cs_raw_cloth, mesh, mesh_fields),
    CYAML_FIELD_MAPPING_PTR("material", OPT, cs_raw_cloth, material, material_fields),
    VEC("velocity", OPT, cs_raw_cloth, velocity, 3),
    CYAML_FIELD_SEQUENCE("pins", OPT, cs_raw_cloth, pins, &selection_value, 0, CYAML_UNLIMITED),
    CYAML_FIELD_SEQUENCE("scripts", OPT, cs_raw_cloth, scripts, &script_value, 0,
                         CYAML_UNLIMITED),
    CYAML_FIELD_END,
};
static const cyaml_schema_value_t cloth_value = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_DEFAULT, cs_raw_cloth, cloth_fields),
};

static const cyaml_schema_field_t body_fields[] = {
    STR("name", cs_raw_body, name),
    CYAML_FIELD_ENUM("shape", CYAML_FLAG_STRICT, cs_raw_body, shape, shape_names,
                     CYAML_ARRAY_LEN(shape_names)),
    VEC("position", OPT, cs_raw_body, position, 3),
    VEC("rotation", OPT, cs_raw_body, rotation, 3),
    VEC("normal", OPT, cs_raw_body, normal, 3),
    NUM("radius", cs_raw_body, radius),
    VEC("size", OPT, cs_raw_body, size, 3),
    NUM("height", cs_raw_body, height),
    NUM("friction", cs_raw_body, friction),
    NUM("collision_offset", cs_raw_body, collision_offset),
    VEC("color", OPT, cs_raw_body, color, 3),
    CYAML_FIELD_MAPPING_PTR("motion", OPT, cs_raw_body, motion, motion_fields),
    CYAML_FIELD_MAPPING_PTR("mesh", OPT, cs_raw_body, mesh, mesh_fields),
    NUM("voxel_size", cs_raw_body, voxel_size),
    NUM("band", cs_raw_body, band),
    BOOL("close_holes", cs_raw_body, close_holes),
    CYAML_FIELD_ENUM_PTR("interior", OPT | CYAML_FLAG_STRICT, cs_raw_body, interior,
                         interior_names, CYAML_ARRAY_LEN(interior_names)),
    CYAML_FIELD_END,
};
static const cyaml_schema_value_t body_value = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_DEFAULT, cs_raw_body, body_fields),
};

static const cyaml_schema_field_t levelset_fields[] = {
    STR("cache", cs_raw_levelset, cache),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t scene_fields[] = {
    STR("name", cs_raw_scene, name),
    STR("description", cs_raw_scene, description),
    CYAML_FIELD_MAPPING_PTR("time", OPT, cs_raw_scene, time, time_fields),
    VEC("gravity", OPT, cs_raw_scene, gravity, 3),
    CYAML_FIELD_MAPPING_PTR("effects", OPT, cs_raw_scene, effects, effects_fields),
    CYAML_FIELD_MAPPING_PTR("self_collision", OPT, cs_raw_scene, self_collision, self_fields),
    CYAML_FIELD_MAPPING_PTR("wind", OPT, cs_raw_scene, wind, wind_fields),
    CYAML_FIELD_MAPPING_PTR("output", OPT, cs_raw_scene, output, output_fields),
    CYAML_FIELD_MAPPING_PTR("camera", OPT, cs_raw_scene, camera, camera_fields),
    CYAML_FIELD_SEQUENCE("cloths", REQ, cs_raw_scene, cloths, &cloth_value, 1, CYAML_UNLIMITED),
    CYAML_FIELD_SEQUENCE("bodies", OPT, cs_raw_scene, bodies, &body_value, 0, CYAML_UNLIMITED),
    CYAML_FIELD_MAPPING_PTR("levelset", OPT, cs_raw_scene, levelset, levelset_fields),
    CYAML_FIELD_END,
};

const cyaml_schema_value_t cs_scene_schema = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_POINTER, cs_raw_scene, scene_fields),
};

/* ------------------------------------------------------------ key paths */

void cs_spath_push_key(cs_spath *p, const char *key, size_t len)
{
    if (p->n >= CS_SPATH_MAX)
        return;
    if (len >= CS_SPATH_KEY)
        len = CS_SPATH_KEY - 1;
    memcpy(p->c[p->n].key, key, len);
    p->c[p->n].key[len] = '\0';
    p->c[p->n].index = -1;
    p->n++;
}

void cs_spath_push_index(cs_spath *p, long index)
{
    if (p->n >= CS_SPATH_MAX)
        return;
    p->c[p->n].key[0] = '\0';
    p->c[p->n].index = index;
    p->n++;
}

bool cs_spath_parse(cs_spath *p, const char *text)
{
    p->n = 0;
    const char *s = text;
    if (*s == '\0')
        return false;
    for (;;) {
        size_t len = strcspn(s, ".[");
        if (len == 0)
            return false;
        cs_spath_push_key(p, s, len);
        s += len;
        while (*s == '[') {
            char *end;
            long index = strtol(s + 1, &end, 10);
            if (end == s + 1 || *end != ']' || index < 0 || s[1] == '-' || s[1] == '+' ||
                s[1] == ' ')
                return false;
            cs_spath_push_index(p, index);
            s = end + 1;
        }
        if (*s == '\0')
            return p->n <= CS_SPATH_MAX;
        if (*s != '.')
            return false;
        s++;
    }
}

bool cs_all_digits(const char *s)
{
    if (*s == '\0')
        return false;
    for (; *s; s++)
        if (*s < '0' || *s > '9')
            return false;
    return true;
}

void cs_spath_format(const cs_spath *p, char *buf, size_t len)
{
    size_t used = 0;
    if (len == 0)
        return;
    buf[0] = '\0';
    for (int i = 0; i < p->n && used < len; i++) {
        int w;
        if (p->c[i].index >= 0)
            w = snprintf(buf + used, len - used, "[%ld]", p->c[i].index);
        else if (i > 0 && cs_all_digits(p->c[i].key))
            w = snprintf(buf + used, len - used, "[%s]", p->c[i].key);
        else
            w = snprintf(buf + used, len - used, "%s%s", i > 0 ? "." : "", p->c[i].key);
        if (w < 0)
            break;
        used += (size_t)w;
    }
}

/* ------------------------------------------------------- schema queries */

const cyaml_schema_value_t *cs_scene_schema_at(const cs_spath *p)
{
    const cyaml_schema_value_t *v = &cs_scene_schema;
    for (int i = 0; i < p->n && v; i++) {
        if (v->type == CYAML_MAPPING) {
            const cyaml_schema_field_t *f = v->mapping.fields;
            while (f->key && strcmp(f->key, p->c[i].key) != 0)
                f++;
            v = f->key ? &f->value : NULL;
        } else if (v->type == CYAML_SEQUENCE || v->type == CYAML_SEQUENCE_FIXED) {
            v = v->sequence.entry;
        } else {
            v = NULL;
        }
    }
    return v;
}

void cs_scene_schema_describe(const cyaml_schema_value_t *v, char *buf, size_t len)
{
    if (!v) {
        snprintf(buf, len, "a valid value");
        return;
    }
    if (v == DT_VALUE) {
        snprintf(buf, len, "a number >= 0 or auto");
        return;
    }
    switch (v->type) {
    case CYAML_INT:
        snprintf(buf, len, "an integer");
        break;
    case CYAML_FLOAT:
        snprintf(buf, len, "a number");
        break;
    case CYAML_BOOL:
        snprintf(buf, len, "true or false");
        break;
    case CYAML_STRING:
        snprintf(buf, len, "a string");
        break;
    case CYAML_ENUM: {
        size_t used = (size_t)snprintf(buf, len, "one of");
        for (uint32_t i = 0; i < v->enumeration.count && used < len; i++)
            used += (size_t)snprintf(buf + used, len - used, "%s %s", i ? "," : "",
                                     v->enumeration.strings[i].str);
        break;
    }
    case CYAML_MAPPING:
        snprintf(buf, len, "a mapping");
        break;
    case CYAML_SEQUENCE_FIXED: {
        const cyaml_schema_value_t *e = v->sequence.entry;
        const char *what = e->type == CYAML_INT     ? "integers"
                           : e->type == CYAML_FLOAT ? "numbers"
                                                    : "values";
        snprintf(buf, len, "a list of %u %s", (unsigned)v->sequence.min, what);
        break;
    }
    case CYAML_SEQUENCE:
        snprintf(buf, len, "a list");
        break;
    default:
        snprintf(buf, len, "a valid value");
        break;
    }
}
