/* scene_emit.c: the resolved scene, the scene.yaml of a run folder.
 *
 * The raw structs (the file with the --set overrides applied) are written
 * back as YAML through libyaml's emitter, key by key in the order of
 * scene_keys.def, every absent key with a default written with it: loading
 * the result gives the same cs_sim_def, so the same frames. What a default
 * is computed from is written as computed (the scene's name, cloth and body
 * names, a mesh body's voxel size). Mesh files are named by their content,
 * assets/<16 hex digits of XXH3-128>/<file name>, relative to the run
 * folder, and the level-set cache is the folder's assets/, where the grids
 * the scene used are copied; cs_scene.assets lists what to copy.
 */
#include "import/scene_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <xxhash.h>
#include <yaml.h>

#define ASSETS "assets"

typedef struct emitter {
    yaml_emitter_t e;
    char *buf;
    size_t len, cap;
    bool failed;
    /* what the keys written by hand come from */
    loader *L;
    cs_scene *s;
    bool frames;      /* write time.frames */
    int cloth, body;  /* the entry being written, or -1 */
    char path[PATH_LEN];
} emitter;

static int write_out(void *data, unsigned char *bytes, size_t size)
{
    emitter *m = data;
    if (m->len + size + 1 > m->cap) {
        size_t cap = m->cap ? m->cap : 4096;
        while (cap < m->len + size + 1)
            cap *= 2;
        char *b = realloc(m->buf, cap);
        if (!b)
            return 0;
        m->buf = b;
        m->cap = cap;
    }
    memcpy(m->buf + m->len, bytes, size);
    m->len += size;
    m->buf[m->len] = '\0';
    return 1;
}

static void put(emitter *m, yaml_event_t *ev, int made)
{
    if (!made || m->failed || !yaml_emitter_emit(&m->e, ev))
        m->failed = true;
}

static void scalar(emitter *m, const char *text, bool quoted)
{
    yaml_event_t ev;
    put(m, &ev,
        yaml_scalar_event_initialize(&ev, NULL, NULL, (yaml_char_t *)text, (int)strlen(text), 1,
                                     1, quoted ? YAML_DOUBLE_QUOTED_SCALAR_STYLE
                                               : YAML_PLAIN_SCALAR_STYLE));
}

/* A mapping or a sequence opens (block or flow style) or closes. */
static void open_node(emitter *m, bool seq, bool flow)
{
    yaml_event_t ev;
    if (seq)
        put(m, &ev, yaml_sequence_start_event_initialize(&ev, NULL, NULL, 1,
                                                         flow ? YAML_FLOW_SEQUENCE_STYLE
                                                              : YAML_BLOCK_SEQUENCE_STYLE));
    else
        put(m, &ev, yaml_mapping_start_event_initialize(&ev, NULL, NULL, 1,
                                                        flow ? YAML_FLOW_MAPPING_STYLE
                                                             : YAML_BLOCK_MAPPING_STYLE));
}

static void close_node(emitter *m, bool seq)
{
    yaml_event_t ev;
    put(m, &ev, seq ? yaml_sequence_end_event_initialize(&ev)
                    : yaml_mapping_end_event_initialize(&ev));
}

#define map_start(m, flow) open_node(m, false, flow)
#define map_end(m) close_node(m, false)
#define seq_start(m, flow) open_node(m, true, flow)
#define seq_end(m) close_node(m, true)

/* The shortest text that reads back as the same double. */
static void number(emitter *m, double v)
{
    char text[40];
    for (int digits = 15; digits <= 17; digits++) {
        snprintf(text, sizeof text, "%.*g", digits, v);
        if (strtod(text, NULL) == v)
            break;
    }
    scalar(m, text, false);
}

static void integer(emitter *m, long v)
{
    char text[24];
    snprintf(text, sizeof text, "%ld", v);
    scalar(m, text, false);
}

static void numbers(emitter *m, const double *v, int n)
{
    seq_start(m, true);
    for (int i = 0; i < n; i++)
        number(m, v[i]);
    seq_end(m);
}

static void integers(emitter *m, const int *v, int n)
{
    seq_start(m, true);
    for (int i = 0; i < n; i++)
        integer(m, v[i]);
    seq_end(m);
}

/* ---------------------------------------------------------------- assets */

static bool add_asset(cs_scene *s, const char *source, const char *name)
{
    for (int i = 0; i < s->nassets; i++)
        if (!strcmp(s->assets[i].name, name))
            return true;
    cs_scene_asset *a = realloc(s->assets, ((size_t)s->nassets + 1) * sizeof *a);
    if (!a)
        return false;
    s->assets = a;
    a[s->nassets].source = cs_sl_strdup(source);
    a[s->nassets].name = cs_sl_strdup(name);
    if (!a[s->nassets].source || !a[s->nassets].name) {
        free(a[s->nassets].source);
        free(a[s->nassets].name);
        return false;
    }
    s->nassets++;
    return true;
}

/* assets/<hash>/<file name> for a mesh file, its hash that of its bytes;
 * NULL when it cannot be read (import read it a moment ago) or memory
 * runs out. */
static char *mesh_asset(cs_scene *s, const char *file)
{
    FILE *f = fopen(file, "rb");
    XXH3_state_t *h = XXH3_createState();
    char *name = NULL;
    if (f && h && XXH3_128bits_reset(h) == XXH_OK) {
        unsigned char buf[65536];
        size_t n;
        while ((n = fread(buf, 1, sizeof buf, f)) > 0)
            XXH3_128bits_update(h, buf, n);
        XXH128_canonical_t c;
        XXH128_canonicalFromHash(&c, XXH3_128bits_digest(h));
        char hex[17];
        for (int i = 0; i < 8; i++)
            snprintf(hex + 2 * i, 3, "%02x", c.digest[i]);
        const char *base = cs_sl_base_name(file);
        size_t len = strlen(ASSETS) + strlen(hex) + strlen(base) + 3;
        if (!ferror(f) && (name = malloc(len)) != NULL) {
            snprintf(name, len, "%s/%s/%s", ASSETS, hex, base);
            if (!add_asset(s, file, name)) {
                free(name);
                name = NULL;
            }
        }
    }
    XXH3_freeState(h);
    if (f)
        fclose(f);
    return name;
}

/* ------------------------------------------------------------ the keys */

static void emit_section(emitter *m, int sec, const void *raw);

/* The member of raw that holds key k: the value itself for a required
 * number or enum, else a pointer (NULL: absent). */
static const void *member(const void *raw, const cs_scene_key *k)
{
    if (!raw)
        return NULL;
    const char *field = (const char *)raw + k->raw;
    if (k->required && (k->type == CS_KT_NUM || k->type == CS_KT_ENUM))
        return field;
    return *(const void *const *)field;
}

static unsigned count_of(const void *raw, const cs_scene_key *k)
{
    return raw ? *(const unsigned *)((const char *)raw + k->count) : 0;
}

/* Whether an absent key's default is written: not where it would clash
 * with a key given instead (the conversion refuses both), nor for a key
 * the body's shape does not use. */
static bool default_applies(int sec, const cs_scene_key *k, const void *raw)
{
    if (sec == CS_SEC_body) {
        const cs_raw_body *b = raw;
        if (k == CS_SKEY(body, rotation))
            return !b->normal;
        if (k == CS_SKEY(body, friction))
            return !b->friction_keys;
        if (k == CS_SKEY(body, radius))
            return false; /* required where used */
        if (k == CS_SKEY(body, band) || k == CS_SKEY(body, close_holes) ||
            k == CS_SKEY(body, interior))
            return b->shape == CS_BODY_MESH;
    }
    if (sec == CS_SEC_mesh && k == CS_SKEY(mesh, units))
        return ((const cs_raw_mesh *)raw)->file != NULL;
    if (sec == CS_SEC_motion && (k == CS_SKEY(motion, velocity) ||
                                 k == CS_SKEY(motion, angular_velocity)))
        return !((const cs_raw_motion *)raw)->keys;
    return true;
}

static void push_path(emitter *m, const char *fmt, const char *key, int index, size_t *saved)
{
    *saved = strlen(m->path);
    size_t used = *saved;
    if (used < sizeof m->path)
        snprintf(m->path + used, sizeof m->path - used, fmt, *m->path && key ? "." : "",
                 key ? key : "", index);
}

/* Keys whose value is not the raw one: 1 when written, 0 to go on, -1
 * to leave the key out. */
static int by_hand(emitter *m, int sec, const cs_scene_key *k, const void *raw)
{
    cs_scene *s = m->s;
    if (k == CS_SKEY(scene, name)) {
        scalar(m, k->key, false);
        scalar(m, s->name, true);
        return 1;
    }
    if (k == CS_SKEY(cloth, name) || k == CS_SKEY(body, name)) {
        scalar(m, k->key, false);
        scalar(m, sec == CS_SEC_cloth ? s->def.cloths[m->cloth].name : s->def.bodies[m->body].name,
               true);
        return 1;
    }
    if (k == CS_SKEY(time, frames) && !m->frames)
        return -1;
    if (k == CS_SKEY(time, dt)) {
        const char *dt = member(raw, k);
        scalar(m, k->key, false);
        if (dt)
            scalar(m, dt, false);
        else if (k->def(0) > 0)
            number(m, k->def(0));
        else
            scalar(m, "auto", false);
        return 1;
    }
    if (k == CS_SKEY(levelset, cache)) {
        scalar(m, k->key, false);
        scalar(m, ASSETS, true);
        return 1;
    }
    if (k == CS_SKEY(body, voxel_size)) {
        const cs_scene_mesh_body *mb = s->mesh_bodies ? &s->mesh_bodies[m->body] : NULL;
        if (!mb || !mb->mesh)
            return -1;
        scalar(m, k->key, false);
        number(m, mb->voxel_size);
        return 1;
    }
    if (k == CS_SKEY(mesh, file)) {
        const char *file = member(raw, k);
        if (!file)
            return -1;
        char *path = cs_sl_scene_relative(m->L->file, file);
        char *name = path ? mesh_asset(s, path) : NULL;
        free(path);
        if (!name) {
            m->failed = true;
            return 1;
        }
        scalar(m, k->key, false);
        scalar(m, name, true);
        free(name);
        return 1;
    }
    if (k->type == CS_KT_SCALE) {
        char p[PATH_LEN + 8];
        double scale[3];
        snprintf(p, sizeof p, "%s.%s", m->path, k->key);
        if (cs_sl_read_scale(m->L, p, scale) != CS_OK)
            m->failed = true;
        scalar(m, k->key, false);
        numbers(m, scale, 3);
        return 1;
    }
    return 0;
}

static void emit_list(emitter *m, const cs_scene_key *k, const void *v, unsigned n)
{
    const cs_scene_section *child = &cs_scene_sections[k->child];
    seq_start(m, false);
    for (unsigned i = 0; i < n; i++) {
        size_t saved;
        push_path(m, "%s%s[%d]", k->key, (int)i, &saved);
        if (k == CS_SKEY(scene, cloths))
            m->cloth = (int)i;
        if (k == CS_SKEY(scene, bodies))
            m->body = (int)i;
        emit_section(m, k->child, (const char *)v + i * child->size);
        m->path[saved] = '\0';
    }
    seq_end(m);
}

static void emit_key(emitter *m, int sec, const cs_scene_key *k, const void *raw)
{
    int hand = by_hand(m, sec, k, raw);
    if (hand)
        return;
    const void *v = member(raw, k);
    bool def = !v && k->def && default_applies(sec, k, raw);
    if (!v && !def && !(k->type == CS_KT_MAP && !strcmp(k->deftext ? k->deftext : "", "see below")))
        return;
    scalar(m, k->key, false);
    switch (k->type) {
    case CS_KT_NUM: number(m, v ? *(const double *)v : k->def(0)); break;
    case CS_KT_INT: integer(m, v ? *(const int *)v : (long)k->def(0)); break;
    case CS_KT_BOOL: scalar(m, (v ? *(const bool *)v : k->def(0) != 0) ? "true" : "false", false);
        break;
    case CS_KT_STR: scalar(m, v, true); break;
    case CS_KT_ENUM:
        scalar(m, cs_scene_enum_name(k, v ? *(const int *)v : (int)k->def(0)), false);
        break;
    case CS_KT_VEC:
    case CS_KT_IVEC: {
        seq_start(m, true);
        for (int i = 0; i < k->n; i++) {
            if (k->type == CS_KT_VEC)
                number(m, v ? ((const double *)v)[i] : k->def(i));
            else
                integer(m, v ? ((const int *)v)[i] : (long)k->def(i));
        }
        seq_end(m);
        break;
    }
    case CS_KT_MAP: {
        size_t saved;
        push_path(m, "%s%s", k->key, 0, &saved);
        emit_section(m, k->child, v);
        m->path[saved] = '\0';
        break;
    }
    case CS_KT_LIST: emit_list(m, k, v, count_of(raw, k)); break;
    case CS_KT_VLIST:
    case CS_KT_ILIST:
        seq_start(m, false);
        for (unsigned i = 0; i < count_of(raw, k); i++) {
            if (k->type == CS_KT_VLIST)
                numbers(m, (const double *)v + (size_t)i * (size_t)k->n, k->n);
            else
                integers(m, (const int *)v + (size_t)i * (size_t)k->n, k->n);
        }
        seq_end(m);
        break;
    case CS_KT_IDXLIST: integers(m, v, (int)count_of(raw, k)); break;
    default: m->failed = true; break; /* DT and SCALE are written by hand */
    }
}

/* A section's keys; raw NULL: an absent block, every key its default. */
static void emit_section(emitter *m, int sec, const void *raw)
{
    map_start(m, false);
    for (int i = 0; i < CS_KEY_COUNT; i++)
        if (cs_scene_keys[i].section == sec)
            emit_key(m, sec, &cs_scene_keys[i], raw);
    map_end(m);
}

static int emit(loader *L, const cs_raw_scene *r, cs_scene *s, bool frames, char **text,
                size_t *len)
{
    emitter *m = calloc(1, sizeof *m);
    if (!m || !yaml_emitter_initialize(&m->e)) {
        free(m);
        return CS_ERR_NOMEM;
    }
    m->L = L;
    m->s = s;
    m->frames = frames;
    m->cloth = m->body = -1;
    yaml_emitter_set_output(&m->e, write_out, m);
    yaml_emitter_set_unicode(&m->e, 1);
    yaml_emitter_set_width(&m->e, 100);
    yaml_event_t ev;
    put(m, &ev, yaml_stream_start_event_initialize(&ev, YAML_UTF8_ENCODING));
    put(m, &ev, yaml_document_start_event_initialize(&ev, NULL, NULL, NULL, 1));
    emit_section(m, CS_SEC_scene, r);
    put(m, &ev, yaml_document_end_event_initialize(&ev, 1));
    put(m, &ev, yaml_stream_end_event_initialize(&ev));
    yaml_emitter_delete(&m->e);
    int rc = m->failed ? (L->err_msg[0] ? CS_ERR_BAD_INPUT : CS_ERR_NOMEM) : CS_OK;
    *text = rc == CS_OK ? m->buf : NULL;
    *len = rc == CS_OK ? m->len : 0;
    if (rc != CS_OK)
        free(m->buf);
    free(m);
    return rc;
}

int cs_sl_resolve(loader *L, const cs_raw_scene *r, cs_scene *s)
{
    L->err_msg[0] = '\0';
    int rc = emit(L, r, s, true, &s->resolved, &s->resolved_len);
    if (rc == CS_OK)
        rc = emit(L, r, s, false, &s->resolved_setup, &s->resolved_setup_len);
    /* the grids the scene used, already named by their content */
    for (int b = 0; rc == CS_OK && s->mesh_bodies && b < s->def.nbodies; b++) {
        const char *cached = s->mesh_bodies[b].cache_path;
        char name[PATH_LEN + 16];
        if (!cached)
            continue;
        snprintf(name, sizeof name, "%s/%s", ASSETS, cs_sl_base_name(cached));
        if (!add_asset(s, cached, name))
            rc = CS_ERR_NOMEM;
    }
    return rc;
}
