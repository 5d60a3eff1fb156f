/* usd_write.c: USD's text format (.usda) written as a stream (usd_write.h).
 *
 * The layout follows what usdcat writes: metadata in parentheses after the
 * `#usda 1.0` line, one attribute a line, time samples as a dictionary of
 * time code to value. A Mesh's subdivisionScheme defaults to catmullClark
 * in USD, which would round the cloth off; it is set to none. */
#include "app/usd_write.h"

#include <stdbool.h>
#include <string.h>

/* ---------------------------------------------------------------- names */

static bool ident_char(unsigned char ch, bool first)
{
    return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || ch == '_' ||
           (!first && ch >= '0' && ch <= '9');
}

static bool taken_by(const char *name, const char *const *taken, int ntaken)
{
    for (int i = 0; i < ntaken; i++)
        if (taken[i] && strcmp(taken[i], name) == 0)
            return true;
    return false;
}

void cs_usd_identifier(const char *name, const char *fallback, const char *const *taken,
                       int ntaken, char *out, size_t len)
{
    const char *s = name && *name ? name : fallback;
    size_t room = len - 16; /* for a leading '_' and a suffix */
    size_t n = 0;
    if (s[0] >= '0' && s[0] <= '9')
        out[n++] = '_';
    for (; *s && n < room; s++, n++)
        out[n] = ident_char((unsigned char)*s, n == 0) ? *s : '_';
    out[n] = '\0';
    for (int k = 2; taken_by(out, taken, ntaken); k++)
        snprintf(out + n, len - n, "_%d", k);
}

/* A string literal: double quotes, with \\ \" \n \t and \xHH for the other
 * control bytes escaped; UTF-8 passes as it is. */
static void put_string(FILE *fp, const char *s)
{
    fputc('"', fp);
    for (; s && *s; s++) {
        unsigned char ch = (unsigned char)*s;
        if (ch == '"' || ch == '\\')
            fprintf(fp, "\\%c", ch);
        else if (ch == '\n')
            fputs("\\n", fp);
        else if (ch == '\t')
            fputs("\\t", fp);
        else if (ch < 0x20 || ch == 0x7f)
            fprintf(fp, "\\x%02x", ch);
        else
            fputc(ch, fp);
    }
    fputc('"', fp);
}

/* --------------------------------------------------------------- stage */

void cs_usd_begin_stage(FILE *fp, const cs_usd_stage *st)
{
    fprintf(fp, "#usda 1.0\n(\n    defaultPrim = ");
    put_string(fp, st->root);
    fprintf(fp, "\n    doc = \"clothsim: one mesh per cloth, points sampled per frame\"\n");
    fprintf(fp, "    endTimeCode = %d\n", st->end);
    fprintf(fp, "    framesPerSecond = %.17g\n", st->fps);
    fprintf(fp, "    metersPerUnit = 1\n");
    fprintf(fp, "    startTimeCode = %d\n", st->start);
    fprintf(fp, "    timeCodesPerSecond = %.17g\n", st->fps);
    fprintf(fp, "    upAxis = ");
    put_string(fp, st->up_axis);
    fprintf(fp, "\n)\n\ndef Xform ");
    put_string(fp, st->root);
    fprintf(fp, "\n{\n");
}

void cs_usd_end_stage(FILE *fp)
{
    fputs("}\n", fp);
}

/* ---------------------------------------------------------------- meshes */

static void put_float3(FILE *fp, double x, double y, double z)
{
    fprintf(fp, "(%.9g, %.9g, %.9g)", (double)(float)x, (double)(float)y, (double)(float)z);
}

void cs_usd_begin_mesh(FILE *fp, const char *prim, const char *name, int nt, const int *tri,
                       const double color[3])
{
    fprintf(fp, "    def Mesh ");
    put_string(fp, prim);
    fprintf(fp, "\n    {\n        int[] faceVertexCounts = [");
    for (int t = 0; t < nt; t++)
        fputs(t ? ", 3" : "3", fp);
    fprintf(fp, "]\n        int[] faceVertexIndices = [");
    for (int i = 0; i < 3 * nt; i++)
        fprintf(fp, i ? ", %d" : "%d", tri[i]);
    fprintf(fp, "]\n        uniform token orientation = \"rightHanded\"\n");
    fprintf(fp, "        color3f[] primvars:displayColor = [");
    put_float3(fp, color[0], color[1], color[2]);
    fprintf(fp, "] (\n            interpolation = \"constant\"\n        )\n");
    fprintf(fp, "        uniform token subdivisionScheme = \"none\"\n");
    fprintf(fp, "        custom string clothsim:name = ");
    put_string(fp, name);
    fputc('\n', fp);
}

void cs_usd_end_mesh(FILE *fp)
{
    fputs("    }\n\n", fp);
}

void cs_usd_points(FILE *fp, int nv, const double *x)
{
    fputs("        point3f[] points = [", fp);
    for (int v = 0; v < nv; v++) {
        if (v)
            fputs(", ", fp);
        put_float3(fp, x[3 * v], x[3 * v + 1], x[3 * v + 2]);
    }
    fputs("]\n", fp);
}

void cs_usd_begin_points_samples(FILE *fp)
{
    fputs("        point3f[] points.timeSamples = {\n", fp);
}

void cs_usd_points_sample(FILE *fp, int code, int nv, const float *x)
{
    fprintf(fp, "            %d: [", code);
    for (int v = 0; v < nv; v++)
        fprintf(fp, v ? ", (%.9g, %.9g, %.9g)" : "(%.9g, %.9g, %.9g)", (double)x[3 * v],
                (double)x[3 * v + 1], (double)x[3 * v + 2]);
    fputs("],\n", fp);
}

void cs_usd_end_samples(FILE *fp)
{
    fputs("        }\n", fp);
}

/* ------------------------------------------------------------ transforms */

/* USD's matrices act on row vectors (p' = p M): M is R transposed over the
 * translation row. */
static void put_matrix(FILE *fp, const double R[9], const double c[3])
{
    fputc('(', fp);
    for (int i = 0; i < 3; i++)
        fprintf(fp, "(%.17g, %.17g, %.17g, 0), ", R[i], R[3 + i], R[6 + i]);
    fprintf(fp, "(%.17g, %.17g, %.17g, 1))", c[0], c[1], c[2]);
}

void cs_usd_transform(FILE *fp, const double R[9], const double c[3])
{
    fputs("        matrix4d xformOp:transform = ", fp);
    put_matrix(fp, R, c);
    fputc('\n', fp);
}

void cs_usd_begin_transform_samples(FILE *fp)
{
    fputs("        matrix4d xformOp:transform.timeSamples = {\n", fp);
}

void cs_usd_transform_sample(FILE *fp, int code, const double R[9], const double c[3])
{
    fprintf(fp, "            %d: ", code);
    put_matrix(fp, R, c);
    fputs(",\n", fp);
}

void cs_usd_transform_order(FILE *fp)
{
    fputs("        uniform token[] xformOpOrder = [\"xformOp:transform\"]\n", fp);
}
