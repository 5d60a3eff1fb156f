/* scene_reference.c: the scene file reference, printed from the table of
 * keys (scene_keys.def): `clothsim help scene`, and with --markdown the
 * tables of docs/scene-reference.md (tests/cli_scene_reference.sh fails
 * when the two disagree). */
#include "import/import.h"

#include <stdio.h>
#include <string.h>

#include "import/scene_schema.h"

/* %g without an exponent's padding: 1e-06 -> 1e-6. */
static void format_number(double x, char *buf, size_t len)
{
    char tmp[32], *e;
    snprintf(tmp, sizeof tmp, "%g", x);
    if ((e = strchr(tmp, 'e')) != NULL) {
        char *d = e + 1;
        bool minus = *d == '-';
        d += *d == '-' || *d == '+';
        while (*d == '0' && d[1])
            d++;
        snprintf(buf, len, "%.*se%s%s", (int)(e - tmp), tmp, minus ? "-" : "", d);
    } else {
        snprintf(buf, len, "%s", tmp);
    }
}

static void type_text(const cs_scene_key *k, char *buf, size_t len)
{
    const char *child = k->child >= 0 ? cs_scene_sections[k->child].tname : "";
    switch (k->type) {
    case CS_KT_NUM: snprintf(buf, len, "number"); break;
    case CS_KT_INT: snprintf(buf, len, "integer"); break;
    case CS_KT_BOOL: snprintf(buf, len, "boolean"); break;
    case CS_KT_STR: snprintf(buf, len, "string"); break;
    case CS_KT_DT: snprintf(buf, len, "number or `auto`"); break;
    case CS_KT_VEC: snprintf(buf, len, "%d numbers", k->n); break;
    case CS_KT_IVEC: snprintf(buf, len, "%d integers", k->n); break;
    case CS_KT_SCALE: snprintf(buf, len, "number or %d numbers", k->n); break;
    case CS_KT_MAP: snprintf(buf, len, "%s", child); break;
    case CS_KT_LIST: snprintf(buf, len, "list of %ss", child); break;
    case CS_KT_VLIST: snprintf(buf, len, "list of %d numbers", k->n); break;
    case CS_KT_ILIST: snprintf(buf, len, "list of %d integers", k->n); break;
    case CS_KT_IDXLIST: snprintf(buf, len, "list of integers"); break;
    case CS_KT_ENUM: {
        size_t used = 0;
        buf[0] = '\0';
        for (unsigned i = 0; i < k->nnames && used < len; i++)
            used += (size_t)snprintf(buf + used, len - used, "%s`%s`",
                                     i == 0              ? ""
                                     : i + 1 < k->nnames ? ", "
                                                         : " or ",
                                     k->names[i].str);
        break;
    }
    }
}

static void default_text(const cs_scene_key *k, char *buf, size_t len)
{
    char num[32];
    if (k->required) {
        snprintf(buf, len, "*required*");
    } else if (k->deftext) {
        snprintf(buf, len, "%s", k->deftext);
    } else if (!k->def) {
        snprintf(buf, len, "none");
    } else if (k->type == CS_KT_BOOL) {
        snprintf(buf, len, "`%s`", k->def(0) != 0 ? "true" : "false");
    } else if (k->type == CS_KT_ENUM) {
        snprintf(buf, len, "`%s`", cs_scene_enum_name(k, (int)k->def(0)));
    } else if (k->type == CS_KT_VEC || k->type == CS_KT_IVEC) {
        size_t used = (size_t)snprintf(buf, len, "`[");
        for (int i = 0; i < k->n && used < len; i++) {
            format_number(k->def(i), num, sizeof num);
            used += (size_t)snprintf(buf + used, len - used, "%s%s", i ? ", " : "", num);
        }
        if (used < len)
            snprintf(buf + used, len - used, "]`");
    } else {
        format_number(k->def(0), num, sizeof num);
        snprintf(buf, len, "%s", num);
    }
}

/* The key's range as the reference says it: "> 0", "each in [0, 1]",
 * "at least 1 entry"; "" for none. */
static void range_text(const cs_scene_key *k, char *buf, size_t len)
{
    const cs_key_range *r = &k->range;
    buf[0] = '\0';
    if (r->lo_kind == CS_BOUND_NONE && r->hi_kind == CS_BOUND_NONE)
        return;
    switch (k->type) {
    case CS_KT_LIST:
    case CS_KT_VLIST:
    case CS_KT_ILIST:
    case CS_KT_IDXLIST:
        snprintf(buf, len, "at least %g %s", r->lo, r->lo == 1 ? "entry" : "entries");
        return;
    case CS_KT_INT:
    case CS_KT_IVEC: {
        int w = snprintf(buf, len, "%s>= %d", k->type == CS_KT_IVEC ? "each " : "", (int)r->lo);
        if (r->hi_kind != CS_BOUND_NONE && w > 0 && (size_t)w < len)
            snprintf(buf + w, len - (size_t)w, ", at most %d", (int)r->hi);
        return;
    }
    default: {
        char text[64];
        cs_key_range_text(r, text, sizeof text);
        bool each = k->type == CS_KT_VEC || k->type == CS_KT_SCALE;
        snprintf(buf, len, "%s%s", each ? "each " : "", text);
        return;
    }
    }
}

static void print_section(FILE *out, int sec, bool markdown)
{
    const cs_scene_section *s = &cs_scene_sections[sec];
    if (markdown)
        fprintf(out,
                "<!-- scene-reference:begin %s -->\n"
                "| Key | Type | Default | Unit | Meaning |\n"
                "|-----|------|---------|------|---------|\n",
                s->name);
    else
        fprintf(out, "\n%s\n", s->heading);
    for (int i = 0; i < CS_KEY_COUNT; i++) {
        const cs_scene_key *k = &cs_scene_keys[i];
        if (k->section != sec)
            continue;
        char type[160], def[160], range[96];
        type_text(k, type, sizeof type);
        default_text(k, def, sizeof def);
        range_text(k, range, sizeof range);
        if (markdown)
            fprintf(out, "| `%s` | %s | %s | %s | %s%s%s |\n", k->key, type, def, k->unit, k->doc,
                    *range ? "; " : "", range);
        else
            fprintf(out, "  %-18s %s; default %s%s%s\n  %-18s %s%s%s\n", k->key, type, def,
                    *k->unit ? "; " : "", k->unit, "", k->doc, *range ? "; " : "", range);
    }
    if (markdown)
        fprintf(out, "<!-- scene-reference:end %s -->\n", s->name);
}

/* Sections from the top level down, each once, where first met. */
static void walk(FILE *out, int sec, bool markdown, bool *done)
{
    if (done[sec])
        return;
    done[sec] = true;
    print_section(out, sec, markdown);
    for (int i = 0; i < CS_KEY_COUNT; i++)
        if (cs_scene_keys[i].section == sec && cs_scene_keys[i].child >= 0)
            walk(out, cs_scene_keys[i].child, markdown, done);
}

void cs_scene_reference(FILE *out, bool markdown)
{
    bool done[CS_SEC_COUNT] = {false};
    if (!markdown)
        fputs("The keys of a scene file (YAML), section by section: type; default; unit,\n"
              "then what the key means and the values it takes. Unknown keys are errors;\n"
              "README.md, \"Scene file reference\", tells more.\n",
              out);
    walk(out, CS_SEC_scene, markdown, done);
}
