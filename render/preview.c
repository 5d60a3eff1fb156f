/* preview.c: the OSMesa preview: rasterised with GLSL 1.30 on Mesa's
 * llvmpipe, same camera, sky, sun and tone curve as the ray tracer, without
 * shadows or bounces.
 *
 * Only libOSMesa is linked (never libGL: with both, glGetString returns NULL
 * and nothing draws); it exports every GL entry point, hence
 * GL_GLEXT_PROTOTYPES. OSMesa's buffer has its rows bottom-up. With samples
 * > 1 the scene is drawn into a multisampled framebuffer and resolved into
 * OSMesa's. Coverage comes out of the alpha channel: the sky writes 0,
 * meshes write 1, and the resolve averages the samples.
 */
#define GL_GLEXT_PROTOTYPES 1
#include <GL/osmesa.h>
#include <GL/gl.h>
#include <GL/glext.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/internal.h"

struct cs_preview {
    OSMesaContext ctx;
    unsigned char *buffer;         /* width x height RGBA, rows bottom-up */
    cs_render_settings settings;
    int msaa;                      /* samples of the offscreen framebuffer; 0: none */
    GLuint fbo, color_rb, depth_rb;
    GLuint mesh_prog, sky_prog;
    GLuint vbo_pos, vbo_normal, ibo;
    GLint u_mvp, u_color, u_eye, u_flat, u_wire;
    GLint s_forward, s_right, s_up, s_scale, s_size;
};

/* ------------------------------------------------------------------ shaders */

/* Shared GLSL: the sky and the tone curve of render/internal.h. */
static const char *glsl_common_fmt =
    "#version 130\n"
    "const vec3 SKY_ZENITH = vec3(%.6f, %.6f, %.6f);\n"
    "const vec3 SKY_HORIZON = vec3(%.6f, %.6f, %.6f);\n"
    "const vec3 SKY_BELOW = vec3(%.6f, %.6f, %.6f);\n"
    "const vec3 SUN_DIR = vec3(%.6f, %.6f, %.6f);\n"
    "const vec3 SUN_E = vec3(%.6f, %.6f, %.6f);\n"
    "const float EXPOSURE = %.6f;\n"
    "vec3 sky(vec3 d) {\n"
    "  if (d.y >= 0.0) return mix(SKY_HORIZON, SKY_ZENITH, sqrt(d.y));\n"
    "  return mix(SKY_HORIZON, SKY_BELOW, min(-d.y * 8.0, 1.0));\n"
    "}\n"
    "float encode1(float v) {\n"
    "  v *= EXPOSURE;\n"
    "  if (!(v > 0.0)) return 0.0;\n"
    "  if (v > 0.8) v = 0.8 + 0.2 * (1.0 - exp(-(v - 0.8) / 0.2));\n"
    "  return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;\n"
    "}\n"
    "vec3 encode(vec3 c) { return vec3(encode1(c.r), encode1(c.g), encode1(c.b)); }\n";

static const char *mesh_vs =
    "uniform mat4 u_mvp;\n"
    "in vec3 a_pos;\n"
    "in vec3 a_normal;\n"
    "out vec3 v_pos;\n"
    "out vec3 v_normal;\n"
    "void main() {\n"
    "  v_pos = a_pos;\n"
    "  v_normal = a_normal;\n"
    "  gl_Position = u_mvp * vec4(a_pos, 1.0);\n"
    "}\n";

/* Sun without shadows plus the sky's irradiance for the normal's tilt
 * (cosine-weighted average radiance: horizon + 0.8 (zenith - horizon)
 * facing up, the ground's below). */
static const char *mesh_fs =
    "uniform vec3 u_color;\n"
    "uniform vec3 u_eye;\n"
    "uniform int u_flat;\n"
    "uniform int u_wire;\n"
    "in vec3 v_pos;\n"
    "in vec3 v_normal;\n"
    "out vec4 frag;\n"
    "void main() {\n"
    "  vec3 n;\n"
    "  if (u_flat != 0) {\n"
    "    n = cross(dFdx(v_pos), dFdy(v_pos));\n"
    "    if (dot(n, u_eye - v_pos) < 0.0) n = -n;\n"
    "  } else {\n"
    "    n = gl_FrontFacing ? v_normal : -v_normal;\n"
    "  }\n"
    "  n = dot(n, n) > 0.0 ? normalize(n) : vec3(0.0, 1.0, 0.0);\n"
    "  vec3 up = mix(SKY_HORIZON, SKY_ZENITH, 0.8);\n"
    "  vec3 ambient = mix(SKY_BELOW, up, 0.5 + 0.5 * n.y);\n"
    "  vec3 c = u_color * (SUN_E * max(dot(n, SUN_DIR), 0.0) + ambient);\n"
    "  if (u_wire != 0) c = u_color * 0.12;\n"
    "  frag = vec4(encode(c), 1.0);\n"
    "}\n";

/* The sky behind everything, from each pixel's camera ray. */
static const char *sky_vs =
    "in vec2 a_pos;\n"
    "void main() { gl_Position = vec4(a_pos, 1.0, 1.0); }\n";

static const char *sky_fs =
    "uniform vec3 s_forward, s_right, s_up;\n"
    "uniform vec2 s_scale;\n"
    "uniform vec2 s_size;\n"
    "out vec4 frag;\n"
    "void main() {\n"
    "  vec2 ndc = 2.0 * gl_FragCoord.xy / s_size - 1.0;\n"
    "  vec3 d = normalize(s_forward + ndc.x * s_scale.x * s_right + ndc.y * s_scale.y * s_up);\n"
    "  frag = vec4(encode(sky(d)), 0.0);\n"
    "}\n";

static GLuint compile(GLenum type, const char *common, const char *body, char *err,
                      size_t errlen)
{
    GLuint sh = glCreateShader(type);
    const char *src[2] = {common, body};
    glShaderSource(sh, 2, src, NULL);
    glCompileShader(sh);
    GLint ok = 0;
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[512] = "";
        glGetShaderInfoLog(sh, sizeof log, NULL, log);
        cs_render_error(err, errlen, "preview: shader does not compile: %s", log);
        glDeleteShader(sh);
        return 0;
    }
    return sh;
}

static GLuint link_program(const char *common, const char *vs, const char *fs,
                           const char *attr0, const char *attr1, char *err, size_t errlen)
{
    GLuint v = compile(GL_VERTEX_SHADER, common, vs, err, errlen);
    GLuint f = v ? compile(GL_FRAGMENT_SHADER, common, fs, err, errlen) : 0;
    if (!f) {
        if (v)
            glDeleteShader(v);
        return 0;
    }
    GLuint p = glCreateProgram();
    glAttachShader(p, v);
    glAttachShader(p, f);
    glBindAttribLocation(p, 0, attr0);
    if (attr1)
        glBindAttribLocation(p, 1, attr1);
    glBindFragDataLocation(p, 0, "frag");
    glLinkProgram(p);
    glDeleteShader(v);
    glDeleteShader(f);
    GLint ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[512] = "";
        glGetProgramInfoLog(p, sizeof log, NULL, log);
        cs_render_error(err, errlen, "preview: shaders do not link: %s", log);
        glDeleteProgram(p);
        return 0;
    }
    return p;
}

/* ------------------------------------------------------------ lifecycle */

static bool make_current(cs_preview *p)
{
    return OSMesaMakeCurrent(p->ctx, p->buffer, GL_UNSIGNED_BYTE, p->settings.width,
                             p->settings.height);
}

cs_preview *cs_preview_create(const cs_render_settings *settings, char *err, size_t errlen)
{
    cs_preview *p = calloc(1, sizeof *p);
    if (!p) {
        cs_render_error(err, errlen, "out of memory");
        return NULL;
    }
    p->settings = *settings;
    p->buffer = malloc(4 * (size_t)settings->width * (size_t)settings->height);
    if (!p->buffer) {
        cs_render_error(err, errlen, "out of memory for a %dx%d preview", settings->width,
                        settings->height);
        free(p);
        return NULL;
    }
    p->ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, NULL);
    if (!p->ctx) {
        cs_render_error(err, errlen, "preview: OSMesa cannot create a GL context");
        free(p->buffer);
        free(p);
        return NULL;
    }
    if (!make_current(p)) {
        cs_render_error(err, errlen, "preview: OSMesa cannot draw a %dx%d image",
                        settings->width, settings->height);
        cs_preview_destroy(p);
        return NULL;
    }

    double sun[3];
    cs_sun_direction(sun);
    char common[2048];
    snprintf(common, sizeof common, glsl_common_fmt, cs_sky_zenith[0], cs_sky_zenith[1],
             cs_sky_zenith[2], cs_sky_horizon[0], cs_sky_horizon[1], cs_sky_horizon[2],
             cs_sky_below[0], cs_sky_below[1], cs_sky_below[2], sun[0], sun[1], sun[2],
             cs_sun_irradiance[0] / M_PI, cs_sun_irradiance[1] / M_PI,
             cs_sun_irradiance[2] / M_PI, (double)CS_EXPOSURE);
    p->mesh_prog = link_program(common, mesh_vs, mesh_fs, "a_pos", "a_normal", err, errlen);
    p->sky_prog = p->mesh_prog ? link_program(common, sky_vs, sky_fs, "a_pos", NULL, err, errlen)
                               : 0;
    if (!p->sky_prog) {
        cs_preview_destroy(p);
        return NULL;
    }
    p->u_mvp = glGetUniformLocation(p->mesh_prog, "u_mvp");
    p->u_color = glGetUniformLocation(p->mesh_prog, "u_color");
    p->u_eye = glGetUniformLocation(p->mesh_prog, "u_eye");
    p->u_flat = glGetUniformLocation(p->mesh_prog, "u_flat");
    p->u_wire = glGetUniformLocation(p->mesh_prog, "u_wire");
    p->s_forward = glGetUniformLocation(p->sky_prog, "s_forward");
    p->s_right = glGetUniformLocation(p->sky_prog, "s_right");
    p->s_up = glGetUniformLocation(p->sky_prog, "s_up");
    p->s_scale = glGetUniformLocation(p->sky_prog, "s_scale");
    p->s_size = glGetUniformLocation(p->sky_prog, "s_size");
    glGenBuffers(1, &p->vbo_pos);
    glGenBuffers(1, &p->vbo_normal);
    glGenBuffers(1, &p->ibo);

    if (settings->samples > 1) {
        GLint max_samples = 0;
        glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
        p->msaa = settings->samples < max_samples ? settings->samples : max_samples;
        if (p->msaa > 1) {
            glGenFramebuffers(1, &p->fbo);
            glGenRenderbuffers(1, &p->color_rb);
            glGenRenderbuffers(1, &p->depth_rb);
            glBindRenderbuffer(GL_RENDERBUFFER, p->color_rb);
            glRenderbufferStorageMultisample(GL_RENDERBUFFER, p->msaa, GL_RGBA8, settings->width,
                                             settings->height);
            glBindRenderbuffer(GL_RENDERBUFFER, p->depth_rb);
            glRenderbufferStorageMultisample(GL_RENDERBUFFER, p->msaa, GL_DEPTH_COMPONENT24,
                                             settings->width, settings->height);
            glBindFramebuffer(GL_FRAMEBUFFER, p->fbo);
            glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                                      p->color_rb);
            glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                                      p->depth_rb);
            if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
                p->msaa = 0;   /* fall back to drawing without multisampling */
            glBindFramebuffer(GL_FRAMEBUFFER, 0);
        } else {
            p->msaa = 0;
        }
    }
    GLenum e = glGetError();
    if (e != GL_NO_ERROR) {
        cs_render_error(err, errlen, "preview: GL error 0x%x while setting up", e);
        cs_preview_destroy(p);
        return NULL;
    }
    return p;
}

void cs_preview_destroy(cs_preview *p)
{
    if (!p)
        return;
    if (p->ctx && make_current(p)) {
        if (p->fbo)
            glDeleteFramebuffers(1, &p->fbo);
        if (p->color_rb)
            glDeleteRenderbuffers(1, &p->color_rb);
        if (p->depth_rb)
            glDeleteRenderbuffers(1, &p->depth_rb);
        if (p->vbo_pos)
            glDeleteBuffers(1, &p->vbo_pos);
        if (p->vbo_normal)
            glDeleteBuffers(1, &p->vbo_normal);
        if (p->ibo)
            glDeleteBuffers(1, &p->ibo);
        if (p->mesh_prog)
            glDeleteProgram(p->mesh_prog);
        if (p->sky_prog)
            glDeleteProgram(p->sky_prog);
    }
    if (p->ctx) {
        /* Unbind first: Mesa keeps the framebuffer of a current context. */
        OSMesaMakeCurrent(NULL, NULL, 0, 0, 0);
        OSMesaDestroyContext(p->ctx);
    }
    free(p->buffer);
    free(p);
}

/* ------------------------------------------------------------------ draw */

/* Column-major P * V for GL, from the shared camera basis. */
static void view_projection(const cs_camera_basis *b, double znear, double zfar, float out[16])
{
    double V[16] = {0}, P[16] = {0};
    const double *r = b->right, *u = b->up, *f = b->forward, *e = b->eye;
    /* V rows: right, up, -forward; V[col * 4 + row]. */
    for (int i = 0; i < 3; i++) {
        V[i * 4 + 0] = r[i];
        V[i * 4 + 1] = u[i];
        V[i * 4 + 2] = -f[i];
    }
    V[12] = -(r[0] * e[0] + r[1] * e[1] + r[2] * e[2]);
    V[13] = -(u[0] * e[0] + u[1] * e[1] + u[2] * e[2]);
    V[14] = f[0] * e[0] + f[1] * e[1] + f[2] * e[2];
    V[15] = 1;
    P[0] = 1.0 / (b->tan_half * b->aspect);
    P[5] = 1.0 / b->tan_half;
    P[10] = (zfar + znear) / (znear - zfar);
    P[11] = -1;
    P[14] = 2 * zfar * znear / (znear - zfar);
    for (int c = 0; c < 4; c++)
        for (int rr = 0; rr < 4; rr++) {
            double s = 0;
            for (int k = 0; k < 4; k++)
                s += P[k * 4 + rr] * V[c * 4 + k];
            out[c * 4 + rr] = (float)s;
        }
}

static int upload_and_draw(cs_preview *p, const cs_prepared_mesh *pm, float *scratch,
                           unsigned *indices)
{
    const cs_render_mesh *m = pm->mesh;
    for (size_t i = 0; i < 3 * (size_t)m->nv; i++)
        scratch[i] = (float)m->x[i];
    for (size_t i = 0; i < 3 * (size_t)m->nt; i++)
        indices[i] = (unsigned)m->tri[i];
    glBindBuffer(GL_ARRAY_BUFFER, p->vbo_pos);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(3 * (size_t)m->nv * sizeof(float)), scratch,
                 GL_STREAM_DRAW);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, NULL);
    glBindBuffer(GL_ARRAY_BUFFER, p->vbo_normal);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(3 * (size_t)m->nv * sizeof(float)), pm->normals,
                 GL_STREAM_DRAW);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, NULL);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, p->ibo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(3 * (size_t)m->nt * sizeof(unsigned)),
                 indices, GL_STREAM_DRAW);
    glUniform3f(p->u_color, (float)m->color[0], (float)m->color[1], (float)m->color[2]);

    glUniform1i(p->u_wire, 0);
    glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    glDrawElements(GL_TRIANGLES, 3 * m->nt, GL_UNSIGNED_INT, NULL);
    if (p->settings.wireframe && !m->backdrop) {
        /* Edges pulled forward by a constant depth offset only: a
         * slope-scaled one lets hidden surfaces through where the cloth is
         * seen at grazing angles. */
        glUniform1i(p->u_wire, 1);
        glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
        glEnable(GL_POLYGON_OFFSET_LINE);
        glPolygonOffset(0.0f, -8.0f);
        glDrawElements(GL_TRIANGLES, 3 * m->nt, GL_UNSIGNED_INT, NULL);
        glDisable(GL_POLYGON_OFFSET_LINE);
        glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    }
    return CS_OK;
}

int cs_preview_draw(cs_preview *p, const cs_prepared_scene *ps, const cs_render_camera *camera,
                    cs_image *image, cs_render_stats *stats, char *err, size_t errlen)
{
    int w = image->width, h = image->height;
    if (!make_current(p)) {
        cs_render_error(err, errlen, "preview: OSMesa cannot make its context current");
        return CS_ERR_FAILED;
    }
    int maxv = 0, maxt = 0;
    for (int m = 0; m < ps->nmeshes; m++) {
        if (ps->meshes[m].mesh->nv > maxv)
            maxv = ps->meshes[m].mesh->nv;
        if (ps->meshes[m].mesh->nt > maxt)
            maxt = ps->meshes[m].mesh->nt;
    }
    float *scratch = malloc(3 * (size_t)maxv * sizeof *scratch);
    unsigned *indices = malloc(3 * (size_t)maxt * sizeof *indices);
    if (!scratch || !indices) {
        free(scratch);
        free(indices);
        cs_render_error(err, errlen, "out of memory");
        return CS_ERR_NOMEM;
    }

    cs_camera_basis b;
    cs_camera_basis_make(camera, w, h, &b);
    /* Depth range from the bounding sphere of everything drawn. */
    double centre[3], radius = 0, dist = 0;
    for (int i = 0; i < 3; i++) {
        centre[i] = 0.5 * (ps->lo[i] + ps->hi[i]);
        radius += 0.25 * (ps->hi[i] - ps->lo[i]) * (ps->hi[i] - ps->lo[i]);
        dist += (centre[i] - b.eye[i]) * b.forward[i];
    }
    radius = sqrt(radius) * 1.01 + 1e-6;
    double zfar = fmax(dist + radius, 1e-3);
    double znear = fmax(dist - radius, zfar * 1e-4);
    float mvp[16];
    view_projection(&b, znear, zfar, mvp);

    glBindFramebuffer(GL_FRAMEBUFFER, p->msaa ? p->fbo : 0);
    glViewport(0, 0, w, h);
    glClearColor(0, 0, 0, 0);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnableVertexAttribArray(0);

    /* The sky: one triangle covering the screen, behind everything. */
    static const float screen[6] = {-1, -1, 3, -1, -1, 3};
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    glUseProgram(p->sky_prog);
    glUniform3f(p->s_forward, (float)b.forward[0], (float)b.forward[1], (float)b.forward[2]);
    glUniform3f(p->s_right, (float)b.right[0], (float)b.right[1], (float)b.right[2]);
    glUniform3f(p->s_up, (float)b.up[0], (float)b.up[1], (float)b.up[2]);
    glUniform2f(p->s_scale, (float)(b.tan_half * b.aspect), (float)b.tan_half);
    glUniform2f(p->s_size, (float)w, (float)h);
    glBindBuffer(GL_ARRAY_BUFFER, p->vbo_pos);
    glBufferData(GL_ARRAY_BUFFER, sizeof screen, screen, GL_STREAM_DRAW);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, NULL);
    glDrawArrays(GL_TRIANGLES, 0, 3);

    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glDepthMask(GL_TRUE);
    glDisable(GL_CULL_FACE);   /* cloth has two sides */
    glUseProgram(p->mesh_prog);
    glUniformMatrix4fv(p->u_mvp, 1, GL_FALSE, mvp);
    glUniform3f(p->u_eye, (float)b.eye[0], (float)b.eye[1], (float)b.eye[2]);
    glUniform1i(p->u_flat, p->settings.flat ? 1 : 0);
    glEnableVertexAttribArray(1);
    for (int m = 0; m < ps->nmeshes; m++)
        upload_and_draw(p, &ps->meshes[m], scratch, indices);
    glDisableVertexAttribArray(1);
    glDisableVertexAttribArray(0);
    free(scratch);
    free(indices);

    if (p->msaa) {
        glBindFramebuffer(GL_READ_FRAMEBUFFER, p->fbo);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
        glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
    }
    glFinish();
    GLenum e = glGetError();
    if (e != GL_NO_ERROR) {
        cs_render_error(err, errlen, "preview: GL error 0x%x while drawing", e);
        return CS_ERR_FAILED;
    }

    /* OSMesa's rows run bottom-up; the image's top-down. */
    long long covered = 0;
    for (int y = 0; y < h; y++) {
        const unsigned char *src = p->buffer + 4 * (size_t)(h - 1 - y) * (size_t)w;
        unsigned char *dst = image->rgb + 3 * (size_t)y * (size_t)w;
        unsigned char *cov = image->coverage + (size_t)y * (size_t)w;
        for (int x = 0; x < w; x++) {
            dst[3 * x] = src[4 * x];
            dst[3 * x + 1] = src[4 * x + 1];
            dst[3 * x + 2] = src[4 * x + 2];
            cov[x] = src[4 * x + 3];
            covered += src[4 * x + 3] > 0;
        }
    }
    stats->covered = covered;
    stats->rays = 0;
    return CS_OK;
}
