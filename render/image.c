/* image.c: 8-bit sRGB images and PNG files through libpng's simplified API. */
#include <errno.h>
#include <png.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/util.h"
#include "render/internal.h"

cs_image *cs_image_create(int width, int height)
{
    if (width < 1 || height < 1 || width > CS_RENDER_MAX_SIZE || height > CS_RENDER_MAX_SIZE)
        return NULL;
    cs_image *img = calloc(1, sizeof *img);
    if (!img)
        return NULL;
    size_t n = (size_t)width * (size_t)height;
    img->width = width;
    img->height = height;
    img->rgb = calloc(3 * n, 1);
    img->coverage = calloc(n, 1);
    if (!img->rgb || !img->coverage) {
        cs_image_destroy(img);
        return NULL;
    }
    return img;
}

void cs_image_destroy(cs_image *img)
{
    if (!img)
        return;
    free(img->rgb);
    free(img->coverage);
    free(img);
}

cs_image *cs_image_shrink(const cs_image *src, int width)
{
    if (!src || width < 1 || width > src->width)
        return NULL;
    int height = (int)((double)src->height * width / src->width + 0.5);
    if (height < 1)
        height = 1;
    cs_image *dst = cs_image_create(width, height);
    if (!dst)
        return NULL;
    /* Box filter in linear light (averaging sRGB codes would darken edges):
     * new pixel (x, y) averages the source pixels whose index falls in its
     * span. */
    float linear[256];
    for (int i = 0; i < 256; i++) {
        float v = (float)i / 255.0f;
        linear[i] = v <= 0.04045f ? v / 12.92f : powf((v + 0.055f) / 1.055f, 2.4f);
    }
    for (int y = 0; y < height; y++) {
        int y0 = (int)((long)y * src->height / height);
        int y1 = (int)((long)(y + 1) * src->height / height);
        if (y1 <= y0)
            y1 = y0 + 1;
        for (int x = 0; x < width; x++) {
            int x0 = (int)((long)x * src->width / width);
            int x1 = (int)((long)(x + 1) * src->width / width);
            if (x1 <= x0)
                x1 = x0 + 1;
            float sum[3] = {0, 0, 0};
            unsigned long cov = 0, n = 0;
            for (int sy = y0; sy < y1; sy++)
                for (int sx = x0; sx < x1; sx++) {
                    size_t i = (size_t)sy * (size_t)src->width + (size_t)sx;
                    for (int c = 0; c < 3; c++)
                        sum[c] += linear[src->rgb[3 * i + c]];
                    cov += src->coverage ? src->coverage[i] : 0;
                    n++;
                }
            size_t o = (size_t)y * (size_t)width + (size_t)x;
            for (int c = 0; c < 3; c++) {
                float v = sum[c] / (float)n;
                float e = v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
                int code = (int)(e * 255.0f + 0.5f);
                dst->rgb[3 * o + c] = (unsigned char)(code < 0 ? 0 : code > 255 ? 255 : code);
            }
            dst->coverage[o] = (unsigned char)((cov + n / 2) / n);
        }
    }
    return dst;
}

/* The image as the PNG file tmp (libpng checks its writes and fclose). */
static int fill_png(const char *tmp, void *ctx, char *why, size_t whylen)
{
    const cs_image *img = ctx;
    png_image png;
    memset(&png, 0, sizeof png);
    png.version = PNG_IMAGE_VERSION;
    png.width = (png_uint_32)img->width;
    png.height = (png_uint_32)img->height;
    png.format = PNG_FORMAT_RGB;
    /* libpng reports a failed fopen only as "could not open file": open it
     * here for the system's reason. */
    errno = 0;
    FILE *fp = fopen(tmp, "wb");
    if (!fp) {
        snprintf(why, whylen, "%s", strerror(errno));
        return -1;
    }
    int ok = png_image_write_to_stdio(&png, fp, 0, img->rgb, 3 * img->width, NULL);
    if (!ok)
        snprintf(why, whylen, "%s", png.message);
    png_image_free(&png);
    errno = 0;
    if (ok && (fflush(fp) != 0 || ferror(fp))) {
        snprintf(why, whylen, "%s", strerror(errno ? errno : EIO));
        ok = 0;
    }
    if (fclose(fp) != 0 && ok) {
        snprintf(why, whylen, "%s", strerror(errno ? errno : EIO));
        ok = 0;
    }
    return ok ? 0 : -1;
}

int cs_image_write_png(const cs_image *img, const char *path, char *err, size_t errlen)
{
    if (!img || !img->rgb || !path || !*path) {
        cs_render_error(err, errlen, "cs_image_write_png: no image or no file name");
        return CS_ERR_FAILED;
    }
    return cs_write_atomic(path, false, fill_png, (void *)img, err, errlen) == 0
               ? CS_OK
               : CS_ERR_FAILED;
}

cs_image *cs_image_read_png(const char *path, char *err, size_t errlen)
{
    FILE *fp = fopen(path, "rb");
    if (!fp) {
        cs_render_error(err, errlen, "cannot read %s: %s", path, strerror(errno));
        return NULL;
    }
    fclose(fp);
    png_image png;
    memset(&png, 0, sizeof png);
    png.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&png, path)) {
        cs_render_error(err, errlen, "cannot read %s: %s", path, png.message);
        return NULL;
    }
    if (png.width < 1 || png.height < 1 || png.width > CS_RENDER_MAX_SIZE ||
        png.height > CS_RENDER_MAX_SIZE) {
        cs_render_error(err, errlen, "%s: unsupported size %ux%u", path, png.width, png.height);
        png_image_free(&png);
        return NULL;
    }
    png.format = PNG_FORMAT_RGB;
    cs_image *img = calloc(1, sizeof *img);
    if (img)
        img->rgb = malloc(PNG_IMAGE_SIZE(png));
    if (!img || !img->rgb) {
        cs_render_error(err, errlen, "cannot read %s: out of memory", path);
        png_image_free(&png);
        cs_image_destroy(img);
        return NULL;
    }
    img->width = (int)png.width;
    img->height = (int)png.height;
    if (!png_image_finish_read(&png, NULL, img->rgb, 3 * img->width, NULL)) {
        cs_render_error(err, errlen, "cannot read %s: %s", path, png.message);
        png_image_free(&png);
        cs_image_destroy(img);
        return NULL;
    }
    return img;
}
