/* input_report.c: the findings of the initial-state check in words: the
 * listing `clothsim check` prints and the verdict `clothsim run` starts
 * with (cs_input_check_start). */
#include "app/input_check.h"
#include "app/input_check_internal.h"

#include "app/exit.h"

#include <stdio.h>

static const struct {
    const char *what; /* after the count */
    bool error;       /* what `run` refuses */
} KINDS[K_COUNT] = {
    [K_CROSS] = {"intersecting triangle pairs between different cloths", true},
    [K_SELF] = {"intersecting triangle pairs within a cloth", true},
    [K_BODY_IN] = {"cloth vertices inside a body", true},
    [K_BODY_EDGE] = {"cloth edges through a body with both ends outside it", false},
    [K_BODY_NEAR] = {"cloth vertices outside a body but closer than the threshold", false},
    [K_SELF_NEAR] = {"vertex-triangle pairs of cloth closer than the thickness", false},
    [K_DEGEN] = {"degenerate triangles (zero or near-zero area)", false},
    [K_NONMANIFOLD] = {"non-manifold edges (in more than two triangles)", false},
};

static const char *body_name(const cs_scene *scene, int b)
{
    const char *n = scene->def.bodies[b].name;
    return n ? n : "?";
}

long cs_input_errors(const report *r)
{
    long n = 0;
    for (int k = 0; k < K_COUNT; k++)
        if (KINDS[k].error)
            n += r->k[k].count;
    return n;
}

static void print_finding(FILE *out, const cloth_set *s, int kind, const finding *f)
{
    const cs_scene *scene = s->scene;
    char at[128];
    snprintf(at, sizeof at, "(%.6g, %.6g, %.6g)", f->pos[0], f->pos[1], f->pos[2]);
    switch (kind) {
    case K_CROSS:
        fprintf(out, "  cloth '%s' triangle %d and cloth '%s' triangle %d, near %s\n",
                cs_cloth_set_name(s, f->cloth), f->a, cs_cloth_set_name(s, f->cloth2), f->b, at);
        break;
    case K_SELF:
        fprintf(out, "  cloth '%s' triangles %d and %d, near %s\n",
                cs_cloth_set_name(s, f->cloth), f->a, f->b, at);
        break;
    case K_BODY_IN:
        fprintf(out, "  cloth '%s' vertex %d at %s: %.4g m inside body '%s'\n",
                cs_cloth_set_name(s, f->cloth), f->a, at, f->value, body_name(scene, f->body));
        break;
    case K_BODY_EDGE:
        fprintf(out, "  cloth '%s' edge %d-%d: %.4g m inside body '%s' at %s\n",
                cs_cloth_set_name(s, f->cloth), f->a, f->b, f->value, body_name(scene, f->body),
                at);
        break;
    case K_BODY_NEAR:
        fprintf(out, "  cloth '%s' vertex %d at %s: %.4g m from body '%s' (threshold %.4g m)\n",
                cs_cloth_set_name(s, f->cloth), f->a, at, f->value, body_name(scene, f->body),
                cs_input_body_threshold(scene, f->body));
        break;
    case K_SELF_NEAR:
        fprintf(out, "  cloth '%s' vertex %d at %s: %.4g m from cloth '%s' triangle %d\n",
                cs_cloth_set_name(s, f->cloth), f->a, at, f->value,
                cs_cloth_set_name(s, f->cloth2), f->b);
        break;
    case K_DEGEN: {
        const int *tv = scene->def.cloths[f->cloth].mesh->tri + 3 * (size_t)f->a;
        fprintf(out, "  cloth '%s' triangle %d (vertices %d %d %d) at %s: area %.3g m^2\n",
                cs_cloth_set_name(s, f->cloth), f->a, tv[0], tv[1], tv[2], at, f->value);
        break;
    }
    case K_NONMANIFOLD:
        fprintf(out, "  cloth '%s' edge %d-%d at %s: in %.0f triangles\n",
                cs_cloth_set_name(s, f->cloth), f->a, f->b, at, f->value);
        break;
    }
}

/* The findings of every kind, errors first: a count and the first 20. */
void cs_input_print_report(FILE *out, const cloth_set *s, const report *r, const char *prefix)
{
    for (int pass = 0; pass < 2; pass++)
        for (int k = 0; k < K_COUNT; k++) {
            const kind_list *l = &r->k[k];
            if (KINDS[k].error != (pass == 0) || l->count == 0)
                continue;
            fprintf(out, "%s%s: %ld %s", prefix, KINDS[k].error ? "error" : "warning", l->count,
                    KINDS[k].what);
            if (k == K_SELF_NEAR)
                fprintf(out, " (%.4g m)", r->thickness);
            if (k == K_BODY_NEAR)
                fprintf(out, " (the larger of the thickness and the body's collision_offset)");
            fputc('\n', out);
            for (int i = 0; i < l->n; i++)
                print_finding(out, s, k, &l->first[i]);
            if (l->count > l->n)
                fprintf(out, "  (first %d of %ld shown)\n", l->n, l->count);
        }
}

/* ------------------------------------------------------------------- run */

int cs_input_check_start(const cs_scene *scene, bool quiet, FILE *err)
{
    cloth_set s;
    report r;
    if (cs_cloth_set_init(&s, scene) != 0 || cs_input_analyse(&s, &r) != 0) {
        cs_cloth_set_free(&s);
        fprintf(err, "clothsim: out of memory checking the initial state of %s\n", scene->path);
        return CS_EXIT_OUTPUT;
    }
    long errors = cs_input_errors(&r);
    int status = CS_EXIT_OK;
    if (errors > 0 && !scene->allow_intersecting_start) {
        fprintf(err, "clothsim: %s: the initial state intersects (%ld finding%s); refused:\n",
                scene->path, errors, errors == 1 ? "" : "s");
        cs_input_print_report(err, &s, &r, "clothsim: ");
        fprintf(err,
                "clothsim: %s: move the cloth apart ('clothsim check %s --fix -o DIR' lifts "
                "vertices out of bodies), or set check: {allow_intersecting_start: true} to run "
                "it anyway\n",
                scene->path, scene->path);
        status = CS_EXIT_INPUT;
    } else if (errors > 0) {
        fprintf(err,
                "clothsim: warning: %s: the cloth starts intersecting (%ld intersecting triangle "
                "pairs, %ld vertices inside a body); check.allow_intersecting_start lets it "
                "run; self-collision keeps such pairs (it prevents crossings, it does not undo "
                "them)\n",
                scene->path, r.k[K_CROSS].count + r.k[K_SELF].count, r.k[K_BODY_IN].count);
    }
    if (status == CS_EXIT_OK && !quiet) {
        long w = 0;
        for (int k = 0; k < K_COUNT; k++)
            w += KINDS[k].error ? 0 : r.k[k].count;
        if (w > 0) {
            fprintf(err, "clothsim: warning: %s: the initial state has", scene->path);
            const char *sep = " ";
            for (int k = 0; k < K_COUNT; k++)
                if (!KINDS[k].error && r.k[k].count > 0) {
                    fprintf(err, "%s%ld %s", sep, r.k[k].count, KINDS[k].what);
                    sep = ", ";
                }
            fprintf(err, "; 'clothsim check %s' lists them\n", scene->path);
        }
    }
    cs_cloth_set_free(&s);
    return status;
}
