/* turntable.c: what turns a set of views into something to look at: a
 * contact sheet composed with cairo, and an animation when ffmpeg happens to
 * be installed (it is not a dependency; without it the animation is skipped). */
#include <cairo.h>
#include <errno.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "common/util.h"
#include "render/internal.h"

extern char **environ;

static cairo_surface_t *surface_of(const cs_image *img)
{
    cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, img->width, img->height);
    if (cairo_surface_status(s) != CAIRO_STATUS_SUCCESS)
        return s;
    cairo_surface_flush(s);
    unsigned char *data = cairo_image_surface_get_data(s);
    int stride = cairo_image_surface_get_stride(s);
    for (int y = 0; y < img->height; y++) {
        unsigned *row = (unsigned *)(void *)(data + (size_t)y * (size_t)stride);
        const unsigned char *src = img->rgb + 3 * (size_t)y * (size_t)img->width;
        for (int x = 0; x < img->width; x++)
            row[x] = (unsigned)src[3 * x] << 16 | (unsigned)src[3 * x + 1] << 8 | src[3 * x + 2];
    }
    cairo_surface_mark_dirty(s);
    return s;
}

/* The sheet as the PNG file tmp. */
static int fill_sheet(const char *tmp, void *ctx, char *why, size_t whylen)
{
    cairo_status_t st = cairo_surface_write_to_png(ctx, tmp);
    if (st == CAIRO_STATUS_SUCCESS)
        return 0;
    snprintf(why, whylen, "%s", cairo_status_to_string(st));
    return -1;
}

int cs_render_contact_sheet(const char *path, int nimages, const cs_image *const *images,
                            const char *const *labels, int columns, int thumb_width, char *err,
                            size_t errlen)
{
    if (nimages < 1 || !images || !images[0] || columns < 1 || thumb_width < 1 ||
        thumb_width > CS_RENDER_MAX_SIZE) {
        cs_render_error(err, errlen, "contact sheet: nothing to compose");
        return CS_RENDER_BAD_INPUT;
    }
    int w = images[0]->width, h = images[0]->height;
    for (int i = 1; i < nimages; i++)
        if (!images[i] || images[i]->width != w || images[i]->height != h) {
            cs_render_error(err, errlen, "contact sheet: the images differ in size");
            return CS_RENDER_BAD_INPUT;
        }
    if (columns > nimages)
        columns = nimages;
    int rows = (nimages + columns - 1) / columns;
    double scale = (double)thumb_width / w;
    int th = (int)(h * scale + 0.5) > 0 ? (int)(h * scale + 0.5) : 1;
    int pad = 6, label_h = labels ? 16 : 0;
    int sheet_w = columns * (thumb_width + pad) + pad;
    int sheet_h = rows * (th + label_h + pad) + pad;
    if (sheet_w > 32767 || sheet_h > 32767) {
        cs_render_error(err, errlen, "contact sheet: %dx%d pixels is too large", sheet_w,
                        sheet_h);
        return CS_RENDER_BAD_INPUT;
    }

    cairo_surface_t *sheet = cairo_image_surface_create(CAIRO_FORMAT_RGB24, sheet_w, sheet_h);
    cairo_t *cr = cairo_create(sheet);
    cairo_set_source_rgb(cr, 0.16, 0.16, 0.17);
    cairo_paint(cr);
    for (int i = 0; i < nimages; i++) {
        int col = i % columns, row = i / columns;
        double x = pad + col * (thumb_width + pad), y = pad + row * (th + label_h + pad);
        cairo_surface_t *s = surface_of(images[i]);
        cairo_save(cr);
        cairo_translate(cr, x, y);
        cairo_scale(cr, scale, scale);
        cairo_set_source_surface(cr, s, 0, 0);
        cairo_pattern_set_filter(cairo_get_source(cr), CAIRO_FILTER_BEST);
        cairo_rectangle(cr, 0, 0, w, h);
        cairo_fill(cr);
        cairo_restore(cr);
        cairo_surface_destroy(s);
        if (labels && labels[i]) {
            cairo_set_source_rgb(cr, 0.85, 0.85, 0.85);
            cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL,
                                   CAIRO_FONT_WEIGHT_NORMAL);
            cairo_set_font_size(cr, 11);
            cairo_move_to(cr, x + 2, y + th + 12);
            cairo_show_text(cr, labels[i]);
        }
    }
    cairo_status_t st = cairo_status(cr);
    cairo_destroy(cr);
    int rc = CS_RENDER_OK;
    if (st != CAIRO_STATUS_SUCCESS) {
        cs_render_error(err, errlen, "contact sheet: cairo: %s", cairo_status_to_string(st));
        rc = CS_RENDER_FAILED;
    } else if (cs_write_atomic(path, false, fill_sheet, sheet, err, errlen) != 0) {
        rc = CS_RENDER_FAILED;
    }
    cairo_surface_destroy(sheet);
    return rc;
}

/* The full path of an executable on the PATH, or false. */
static bool find_on_path(const char *name, char *out, size_t len)
{
    const char *path = getenv("PATH");
    if (!path || !*path)
        return false;
    const char *s = path;
    while (*s) {
        const char *e = strchr(s, ':');
        size_t n = e ? (size_t)(e - s) : strlen(s);
        if (n > 0 && (size_t)snprintf(out, len, "%.*s/%s", (int)n, s, name) < len &&
            access(out, X_OK) == 0)
            return true;
        if (!e)
            break;
        s = e + 1;
    }
    return false;
}

int cs_render_animation(const char *pattern, double fps, const char *path, char *err,
                        size_t errlen)
{
    char ffmpeg[4096];
    if (!find_on_path("ffmpeg", ffmpeg, sizeof ffmpeg))
        return 0;
    char rate[32];
    snprintf(rate, sizeof rate, "%g", fps > 0 ? fps : 12.0);
    size_t len = strlen(path);
    bool gif = len >= 4 && strcmp(path + len - 4, ".gif") == 0;
    /* A palette made from the frames keeps a GIF's colours; MP4 players want
     * yuv420p and even sides. */
    const char *filter = gif ? "split[a][b];[a]palettegen[p];[b][p]paletteuse"
                             : "pad=ceil(iw/2)*2:ceil(ih/2)*2";
    char *argv[] = {ffmpeg, "-nostdin", "-v", "error", "-y", "-framerate", rate,
                    "-i", (char *)pattern, "-vf", (char *)filter, "-pix_fmt",
                    gif ? "pal8" : "yuv420p", (char *)path, NULL};
    pid_t pid;
    int rc = posix_spawn(&pid, ffmpeg, NULL, NULL, argv, environ);
    if (rc != 0) {
        cs_render_error(err, errlen, "cannot start %s: %s", ffmpeg, strerror(rc));
        return CS_RENDER_FAILED;
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) {
            cs_render_error(err, errlen, "waiting for ffmpeg: %s", strerror(errno));
            return CS_RENDER_FAILED;
        }
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        cs_render_error(err, errlen, "ffmpeg could not make %s (status %d)", path,
                        WIFEXITED(status) ? WEXITSTATUS(status) : -1);
        return CS_RENDER_FAILED;
    }
    return 1;
}
