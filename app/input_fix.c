/* input_fix.c: `clothsim check --fix -o DIR`: cloth vertices lifted out
 * of the bodies, and the fixed cloths written with the scene lines that
 * use them. */
#include "app/input_check_internal.h"

#include "common/util.h"
#include "import/import.h"
#include "sim/sim.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Lifts every vertex closer than cs_input_body_threshold to a body (or
 * inside it) out along the body's gradient to the threshold, for a few
 * rounds (a vertex between two bodies may be pushed back and forth). */
void cs_input_fix_bodies(cloth_set *s, fix_result *fr)
{
    memset(fr, 0, sizeof *fr);
    const cs_scene *scene = s->scene;
    if (!cs_input_bodies_on(scene))
        return;
    for (int v = 0; v < s->nv; v++) {
        double *x = s->x + 3 * (size_t)v, x0[3];
        memcpy(x0, x, sizeof x0);
        bool clear = false;
        for (int round = 0; round < 8 && !clear; round++) {
            clear = true;
            for (int b = 0; b < scene->def.nbodies; b++) {
                double g[3], thr = cs_input_body_threshold(scene, b);
                double phi = cs_body_def_phi(&scene->def.bodies[b], 0.0, x, g);
                if (phi >= thr)
                    continue;
                clear = false;
                double gl = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
                if (!(gl > 0.5)) /* no gradient (deep in a band-limited grid) */
                    continue;
                double target = thr * (1 + 1e-6) + 1e-12;
                for (int k = 0; k < 3; k++)
                    x[k] += (target - phi) * g[k] / gl;
            }
        }
        double d = cs_dist3(x, x0);
        if (d > 0) {
            fr->moved++;
            fr->max_move = fmax(fr->max_move, d);
        }
        for (int b = 0; b < scene->def.nbodies; b++) {
            double g[3];
            if (cs_body_def_phi(&scene->def.bodies[b], 0.0, x, g) <
                cs_input_body_threshold(scene, b)) {
                fr->stuck++;
                break;
            }
        }
    }
}

/* A cloth's name made safe for a file name. */
static void safe_name(const char *name, int c, char *buf, size_t len)
{
    snprintf(buf, len, "%s", name && *name ? name : "cloth");
    for (char *p = buf; *p; p++)
        if (!((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') ||
              *p == '-' || *p == '_'))
            *p = '_';
    (void)c;
}

/* DIR/NAME.ply per cloth (the fixed positions, world coordinates) and
 * DIR/cloths.yaml, the snippet that uses them. */
int cs_input_write_fixed(const cloth_set *s, const char *dir, char *err, size_t errlen)
{
    if (cs_make_dirs(dir) != 0) {
        snprintf(err, errlen, "cannot make the folder %s: %s", dir, strerror(errno));
        return -1;
    }
    char *abs = realpath(dir, NULL);
    const char *base = abs ? abs : dir;
    size_t cap = 4096 + (size_t)s->ncloths * 1200;
    char *yaml = malloc(cap);
    if (!yaml) {
        free(abs);
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    size_t n = (size_t)snprintf(
        yaml, cap,
        "# clothsim check --fix %s: the cloths with their vertices lifted out of the\n"
        "# bodies. Replace each cloth's grid: or mesh: block with the mesh: below (the\n"
        "# file holds world positions: no scale, rotation or translate) and keep its\n"
        "# other keys. Pins and scripts selected by grid_points must become vertices:\n"
        "# lists (vertex j * (resolution[0] + 1) + i). The vertex numbering is kept\n"
        "# unless the import drops zero-area triangles or unreferenced vertices (it\n"
        "# says so when it loads the scene).\n"
        "cloths:\n",
        s->scene->path);
    int rc = 0;
    for (int c = 0; c < s->ncloths && rc == 0; c++) {
        char name[256], path[4096];
        safe_name(s->scene->def.cloths[c].name, c, name, sizeof name);
        /* a name taken by an earlier cloth gets the index */
        for (int d = 0; d < c; d++) {
            char other[256];
            safe_name(s->scene->def.cloths[d].name, d, other, sizeof other);
            if (strcmp(other, name) == 0) {
                snprintf(name, sizeof name, "cloth%d", c);
                break;
            }
        }
        snprintf(path, sizeof path, "%s/%s.ply", base, name);
        const cs_trimesh *m = s->scene->def.cloths[c].mesh;
        cs_mesh_view view = {cs_cloth_set_name(s, c), m->nv, s->x + 3 * (size_t)s->voff[c], m->nt,
                             m->tri};
        if (cs_mesh_write(path, CS_MESH_PLY, 1, &view, err, errlen) != CS_OK)
            rc = -1;
        else if (n < cap)
            n += (size_t)snprintf(yaml + n, cap - n, "  - name: %s\n    mesh: {file: \"%s\"}\n",
                                  cs_cloth_set_name(s, c), path);
    }
    if (rc == 0) {
        char ypath[4096];
        snprintf(ypath, sizeof ypath, "%s/cloths.yaml", base);
        rc = cs_file_write_atomic(ypath, yaml, strlen(yaml), err, errlen);
    }
    free(yaml);
    free(abs);
    return rc;
}
