/* run_identity.c: what a run is made from and the hashes of its
 * definition and of a frame's state, through xxHash (XXH3-128), in every
 * build (checkpoint.h; state.h5 itself is checkpoint.c's). */
#include "app/checkpoint.h"

#include "common/util.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <xxhash.h>

/* ----------------------------------------------------------------- hashes */

static void hash_hex(XXH3_state_t *h, char hex[CS_STATE_HASH_LEN])
{
    XXH128_canonical_t c;
    XXH128_canonicalFromHash(&c, XXH3_128bits_digest(h));
    for (size_t i = 0; i < sizeof c.digest; i++)
        snprintf(hex + 2 * i, 3, "%02x", c.digest[i]);
}

/* Hashes count arrays of 3n doubles each, in order. An allocation failure
 * gives the empty string, never a wrong hash. */
static void hash_arrays(const cs_sim *sim, const void *head, size_t head_len,
                        const double *const *arrays, int count, char hex[CS_STATE_HASH_LEN])
{
    hex[0] = '\0';
    XXH3_state_t *h = XXH3_createState();
    if (!h || XXH3_128bits_reset(h) != XXH_OK) {
        XXH3_freeState(h);
        return;
    }
    size_t bytes = sizeof(double) * 3 * (size_t)cs_sim_particle_count(sim);
    XXH3_128bits_update(h, head, head_len);
    for (int k = 0; k < count; k++)
        XXH3_128bits_update(h, arrays[k], bytes);
    hash_hex(h, hex);
    XXH3_freeState(h);
}

void cs_state_hash(const cs_sim *sim, char hex[CS_STATE_HASH_LEN])
{
    const double *arrays[] = {cs_sim_positions(sim), cs_sim_velocities(sim)};
    hash_arrays(sim, NULL, 0, arrays, 2, hex);
}

int cs_run_identity_init(cs_run_identity *id, const char *scene_file, int noverrides,
                         const char *const *overrides, const char *format, const cs_sim *sim,
                         const cs_scene *scene, char *err, size_t errlen)
{
    memset(id, 0, sizeof *id);
    id->scene_file = scene_file;
    id->noverrides = noverrides;
    id->overrides = overrides;
    id->format = format;
    id->particles = cs_sim_particle_count(sim);
    id->resolved = scene->resolved_setup;
    id->resolved_len = scene->resolved_setup_len;
    id->scene_text = cs_file_read_all(scene_file, &id->scene_len);
    if (!id->scene_text) {
        snprintf(err, errlen, "cannot read %s: %s", scene_file, strerror(errno));
        return -1;
    }
    /* masses are 1 per particle: hashed as 3n doubles they would overrun */
    int n = id->particles;
    double *mass3 = calloc(3 * (size_t)n + 1, sizeof *mass3);
    if (!mass3) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    memcpy(mass3, cs_sim_masses(sim), sizeof(double) * (size_t)n);
    /* a body's mesh file may change under the same scene text: its mesh
     * as imported, body by body */
    XXH128_hash_t bodies = {0, 0};
    XXH3_state_t *h = XXH3_createState();
    if (h && XXH3_128bits_reset(h) == XXH_OK) {
        for (int b = 0; b < scene->def.nbodies && scene->mesh_bodies; b++) {
            const cs_trimesh *m = scene->mesh_bodies[b].mesh;
            if (!m)
                continue;
            XXH3_128bits_update(h, &b, sizeof b);
            XXH3_128bits_update(h, m->x, sizeof *m->x * 3 * (size_t)m->nv);
            XXH3_128bits_update(h, m->tri, sizeof *m->tri * 3 * (size_t)m->nt);
        }
        bodies = XXH3_128bits_digest(h);
    }
    XXH3_freeState(h);
    struct {
        double n, dt;
        XXH128_hash_t bodies;
    } head = {(double)n, cs_sim_dt(sim), bodies};
    const double *arrays[] = {cs_sim_positions(sim), cs_sim_velocities(sim), mass3};
    hash_arrays(sim, &head, sizeof head, arrays, 3, id->definition_hash);
    free(mass3);
    return 0;
}

void cs_run_identity_free(cs_run_identity *id)
{
    free(id->scene_text);
    id->scene_text = NULL;
}
