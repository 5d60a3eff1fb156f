/* turntable.c: what turns a set of images into something to look at: a
 * contact sheet composed with cairo, and an animation (MP4 or GIF) of
 * numbered PNGs through the ffmpeg program -- turntables and `clothsim
 * render --animation` alike. scripts/install-deps.sh installs ffmpeg, but
 * the build does not need it: without it the animation is skipped and the
 * caller says so. */
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
        return CS_ERR_BAD_INPUT;
    }
    int w = images[0]->width, h = images[0]->height;
    for (int i = 1; i < nimages; i++)
        if (!images[i] || images[i]->width != w || images[i]->height != h) {
            cs_render_error(err, errlen, "contact sheet: the images differ in size");
            return CS_ERR_BAD_INPUT;
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
        return CS_ERR_BAD_INPUT;
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
    int rc = CS_OK;
    if (st != CAIRO_STATUS_SUCCESS) {
        cs_render_error(err, errlen, "contact sheet: cairo: %s", cairo_status_to_string(st));
        rc = CS_ERR_FAILED;
    } else if (cs_write_atomic(path, false, fill_sheet, sheet, err, errlen) != 0) {
        rc = CS_ERR_FAILED;
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

typedef struct animation_job {
    const char *ffmpeg, *pattern, *rate, *first, *count;
    bool gif;
} animation_job;

/* Runs ffmpeg to write the animation as tmp (cs_write_atomic's filler). Its
 * own messages (-v error) go to our stderr. */
static int fill_animation(const char *tmp, void *ctx, char *why, size_t whylen)
{
    const animation_job *a = ctx;
    /* A palette made from the frames keeps a GIF's colours; MP4 is H.264 in
     * yuv420p, which needs even sides, and starts playing before it has all
     * arrived (faststart). */
    char *gif_argv[] = {(char *)a->ffmpeg, "-nostdin", "-v", "error", "-y",
                        "-framerate", (char *)a->rate, "-start_number", (char *)a->first,
                        "-i", (char *)a->pattern, "-frames:v", (char *)a->count,
                        "-vf", "split[a][b];[a]palettegen[p];[b][p]paletteuse",
                        "-f", "gif", (char *)tmp, NULL};
    char *mp4_argv[] = {(char *)a->ffmpeg, "-nostdin", "-v", "error", "-y",
                        "-framerate", (char *)a->rate, "-start_number", (char *)a->first,
                        "-i", (char *)a->pattern, "-frames:v", (char *)a->count,
                        "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264",
                        "-pix_fmt", "yuv420p", "-movflags", "+faststart",
                        "-f", "mp4", (char *)tmp, NULL};
    pid_t pid;
    int rc = posix_spawn(&pid, a->ffmpeg, NULL, NULL, a->gif ? gif_argv : mp4_argv, environ);
    if (rc != 0) {
        snprintf(why, whylen, "cannot start %s: %s", a->ffmpeg, strerror(rc));
        return -1;
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) {
            snprintf(why, whylen, "waiting for ffmpeg: %s", strerror(errno));
            return -1;
        }
    if (WIFSIGNALED(status)) {
        snprintf(why, whylen, "ffmpeg was killed by signal %d", WTERMSIG(status));
        return -1;
    }
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        snprintf(why, whylen, "ffmpeg failed (exit status %d)",
                 WIFEXITED(status) ? WEXITSTATUS(status) : -1);
        return -1;
    }
    if (access(tmp, F_OK) != 0) {
        snprintf(why, whylen, "ffmpeg exited 0 but wrote nothing");
        return -1;
    }
    return 0;
}

int cs_render_animation(const char *pattern, int first, int count, double fps,
                        const char *path, char *err, size_t errlen)
{
    char ffmpeg[4096];
    if (!find_on_path("ffmpeg", ffmpeg, sizeof ffmpeg))
        return 0;
    if (first < 0 || count < 1) {
        cs_render_error(err, errlen, "animation %s: no frames", path);
        return CS_ERR_BAD_INPUT;
    }
    char rate[32], first_s[16], count_s[16];
    snprintf(rate, sizeof rate, "%.17g", fps > 0 ? fps : 12.0);
    snprintf(first_s, sizeof first_s, "%d", first);
    snprintf(count_s, sizeof count_s, "%d", count);
    size_t len = strlen(path);
    animation_job a = {ffmpeg, pattern, rate, first_s, count_s,
                       len >= 4 && strcmp(path + len - 4, ".gif") == 0};
    if (cs_write_atomic(path, false, fill_animation, &a, err, errlen) != 0)
        return CS_ERR_FAILED;
    return 1;
}
