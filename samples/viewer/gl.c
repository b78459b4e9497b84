/* OpenGL 3.3 core with a loader of its own: every function the viewer calls is fetched
 * through glfwGetProcAddress, so there is no loader library to vendor and no link against
 * libGL (GLFW opens the driver). */
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <GL/glcorearb.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl.h"

/* X(type, name): every GL entry point used below. */
#define VW_GL_FUNCS(X)                                                                             \
    X(PFNGLCLEARPROC, glClear)                                                                     \
    X(PFNGLCLEARCOLORPROC, glClearColor)                                                           \
    X(PFNGLVIEWPORTPROC, glViewport)                                                               \
    X(PFNGLENABLEPROC, glEnable)                                                                   \
    X(PFNGLDISABLEPROC, glDisable)                                                                 \
    X(PFNGLBLENDFUNCPROC, glBlendFunc)                                                             \
    X(PFNGLFINISHPROC, glFinish)                                                                   \
    X(PFNGLGETERRORPROC, glGetError)                                                               \
    X(PFNGLGETSTRINGPROC, glGetString)                                                             \
    X(PFNGLPIXELSTOREIPROC, glPixelStorei)                                                         \
    X(PFNGLREADPIXELSPROC, glReadPixels)                                                           \
    X(PFNGLREADBUFFERPROC, glReadBuffer)                                                           \
    X(PFNGLDRAWELEMENTSPROC, glDrawElements)                                                       \
    X(PFNGLDRAWARRAYSPROC, glDrawArrays)                                                           \
    X(PFNGLCREATESHADERPROC, glCreateShader)                                                       \
    X(PFNGLSHADERSOURCEPROC, glShaderSource)                                                       \
    X(PFNGLCOMPILESHADERPROC, glCompileShader)                                                     \
    X(PFNGLGETSHADERIVPROC, glGetShaderiv)                                                         \
    X(PFNGLGETSHADERINFOLOGPROC, glGetShaderInfoLog)                                               \
    X(PFNGLCREATEPROGRAMPROC, glCreateProgram)                                                     \
    X(PFNGLATTACHSHADERPROC, glAttachShader)                                                       \
    X(PFNGLLINKPROGRAMPROC, glLinkProgram)                                                         \
    X(PFNGLGETPROGRAMIVPROC, glGetProgramiv)                                                       \
    X(PFNGLGETPROGRAMINFOLOGPROC, glGetProgramInfoLog)                                             \
    X(PFNGLDELETESHADERPROC, glDeleteShader)                                                       \
    X(PFNGLDELETEPROGRAMPROC, glDeleteProgram)                                                     \
    X(PFNGLUSEPROGRAMPROC, glUseProgram)                                                           \
    X(PFNGLGETUNIFORMLOCATIONPROC, glGetUniformLocation)                                           \
    X(PFNGLUNIFORMMATRIX4FVPROC, glUniformMatrix4fv)                                               \
    X(PFNGLUNIFORM3FVPROC, glUniform3fv)                                                           \
    X(PFNGLUNIFORM4FVPROC, glUniform4fv)                                                           \
    X(PFNGLUNIFORM1IPROC, glUniform1i)                                                             \
    X(PFNGLGENVERTEXARRAYSPROC, glGenVertexArrays)                                                 \
    X(PFNGLBINDVERTEXARRAYPROC, glBindVertexArray)                                                 \
    X(PFNGLDELETEVERTEXARRAYSPROC, glDeleteVertexArrays)                                           \
    X(PFNGLGENBUFFERSPROC, glGenBuffers)                                                           \
    X(PFNGLBINDBUFFERPROC, glBindBuffer)                                                           \
    X(PFNGLBUFFERDATAPROC, glBufferData)                                                           \
    X(PFNGLBUFFERSUBDATAPROC, glBufferSubData)                                                     \
    X(PFNGLDELETEBUFFERSPROC, glDeleteBuffers)                                                     \
    X(PFNGLENABLEVERTEXATTRIBARRAYPROC, glEnableVertexAttribArray)                                 \
    X(PFNGLVERTEXATTRIBPOINTERPROC, glVertexAttribPointer)                                         \
    X(PFNGLGENTEXTURESPROC, glGenTextures)                                                         \
    X(PFNGLBINDTEXTUREPROC, glBindTexture)                                                         \
    X(PFNGLDELETETEXTURESPROC, glDeleteTextures)                                                   \
    X(PFNGLTEXIMAGE2DPROC, glTexImage2D)                                                           \
    X(PFNGLTEXPARAMETERIPROC, glTexParameteri)

#define VW_GL_DECLARE(type, name) static type p_##name;
VW_GL_FUNCS(VW_GL_DECLARE)

static const char *mesh_vs =
    "#version 330 core\n"
    "layout(location=0) in vec3 p; layout(location=1) in vec3 n; layout(location=2) in vec3 c;\n"
    "uniform mat4 vp; uniform vec3 off; out vec3 vn; out vec3 vc;\n"
    "void main() { vn = n; vc = c; gl_Position = vp * vec4(p + off, 1.0); }\n";
/* Two-sided: a render mesh's normals may face either way where the file is careless. */
static const char *mesh_fs = "#version 330 core\n"
                             "in vec3 vn; in vec3 vc; out vec4 o;\n"
                             "void main() {\n"
                             "  vec3 n = normalize(vn); vec3 l = normalize(vec3(0.3, 0.8, 0.6));\n"
                             "  float d = abs(dot(n, l)); float f = 0.25 + 0.75 * d;\n"
                             "  o = vec4(vc * f, 1.0);\n"
                             "}\n";
static const char *hud_vs =
    "#version 330 core\n"
    "uniform vec4 rect; out vec2 uv;\n"
    "void main() {\n"
    "  vec2 k = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1));\n"
    "  uv = vec2(k.x, 1.0 - k.y);\n"
    "  gl_Position = vec4(rect.x + k.x * rect.z, rect.y + k.y * rect.w, 0.0, 1.0);\n"
    "}\n";
static const char *hud_fs =
    "#version 330 core\n"
    "uniform sampler2D tex; in vec2 uv; out vec4 o;\n"
    "void main() { vec3 c = texture(tex, uv).rgb; if (c.r + c.g + c.b == 0.0) discard;\n"
    "  o = vec4(c, 1.0); }\n";

static unsigned mesh_prog, hud_prog, hud_tex, hud_vao, line_vao, line_vbo[3];
static size_t line_cap; /* vertices line_vbo holds */
static float *line_nrm; /* and their normals, as many (grown with it, not each frame) */
static int loc_vp, loc_off, loc_rect, loc_tex;

static unsigned compile(unsigned type, const char *src, char *err, size_t errlen) {
    unsigned s = p_glCreateShader(type);
    int ok = 0;
    p_glShaderSource(s, 1, &src, NULL);
    p_glCompileShader(s);
    p_glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[512] = {0};
        p_glGetShaderInfoLog(s, sizeof log, NULL, log);
        snprintf(err, errlen, "a shader does not compile: %s", log);
        p_glDeleteShader(s);
        return 0;
    }
    return s;
}

static unsigned program(const char *vs, const char *fs, char *err, size_t errlen) {
    unsigned v = compile(GL_VERTEX_SHADER, vs, err, errlen);
    unsigned f = v ? compile(GL_FRAGMENT_SHADER, fs, err, errlen) : 0;
    if (!f) return 0;
    unsigned p = p_glCreateProgram();
    int ok = 0;
    p_glAttachShader(p, v);
    p_glAttachShader(p, f);
    p_glLinkProgram(p);
    p_glDeleteShader(v);
    p_glDeleteShader(f);
    p_glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[512] = {0};
        p_glGetProgramInfoLog(p, sizeof log, NULL, log);
        snprintf(err, errlen, "a shader program does not link: %s", log);
        p_glDeleteProgram(p);
        return 0;
    }
    return p;
}

int vw_gl_init(char *err, size_t errlen) {
#define VW_GL_LOAD(type, name)                                                                     \
    p_##name = (type)glfwGetProcAddress(#name);                                                    \
    if (!p_##name) {                                                                               \
        snprintf(err, errlen, "the GL context lacks %s", #name);                                   \
        return 0;                                                                                  \
    }
    VW_GL_FUNCS(VW_GL_LOAD)
#undef VW_GL_LOAD
    mesh_prog = program(mesh_vs, mesh_fs, err, errlen);
    hud_prog = mesh_prog ? program(hud_vs, hud_fs, err, errlen) : 0;
    if (!hud_prog) return 0;
    loc_vp = p_glGetUniformLocation(mesh_prog, "vp");
    loc_off = p_glGetUniformLocation(mesh_prog, "off");
    loc_rect = p_glGetUniformLocation(hud_prog, "rect");
    loc_tex = p_glGetUniformLocation(hud_prog, "tex");
    p_glGenTextures(1, &hud_tex);
    p_glBindTexture(GL_TEXTURE_2D, hud_tex);
    p_glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    p_glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    p_glGenVertexArrays(1, &hud_vao); /* core profile: a draw needs a bound VAO */
    p_glGenVertexArrays(1, &line_vao);
    p_glBindVertexArray(line_vao);
    p_glGenBuffers(3, line_vbo);
    for (unsigned k = 0; k < 3; ++k) {
        p_glBindBuffer(GL_ARRAY_BUFFER, line_vbo[k]);
        p_glEnableVertexAttribArray(k);
        p_glVertexAttribPointer(k, 3, GL_FLOAT, GL_FALSE, 0, NULL);
    }
    p_glBindVertexArray(0);
    return 1;
}

void vw_gl_shutdown(void) {
    if (!p_glDeleteProgram) return;
    p_glDeleteProgram(mesh_prog);
    p_glDeleteProgram(hud_prog);
    p_glDeleteTextures(1, &hud_tex);
    p_glDeleteVertexArrays(1, &hud_vao);
    p_glDeleteBuffers(3, line_vbo);
    p_glDeleteVertexArrays(1, &line_vao);
    line_cap = 0;
    free(line_nrm), line_nrm = NULL;
}

int vw_glmesh_create(vw_glmesh *m, int32_t nverts, const uint32_t *tris, int32_t ntris) {
    memset(m, 0, sizeof *m);
    m->nverts = nverts, m->ntris = ntris;
    p_glGenVertexArrays(1, &m->vao);
    p_glBindVertexArray(m->vao);
    p_glGenBuffers(3, m->vbo);
    for (unsigned k = 0; k < 3; ++k) {
        p_glBindBuffer(GL_ARRAY_BUFFER, m->vbo[k]);
        p_glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(sizeof(float) * 3 * (size_t)nverts), NULL,
                       GL_STREAM_DRAW);
        p_glEnableVertexAttribArray(k);
        p_glVertexAttribPointer(k, 3, GL_FLOAT, GL_FALSE, 0, NULL);
    }
    p_glGenBuffers(1, &m->ebo);
    p_glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, m->ebo);
    p_glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(sizeof(uint32_t) * 3 * (size_t)ntris),
                   tris, GL_STATIC_DRAW);
    p_glBindVertexArray(0);
    return p_glGetError() == GL_NO_ERROR;
}

void vw_glmesh_update(vw_glmesh *m, const float *pos, const float *nrm, const float *col) {
    const float *src[3] = {pos, nrm, col};
    for (int k = 0; k < 3; ++k) {
        p_glBindBuffer(GL_ARRAY_BUFFER, m->vbo[k]);
        p_glBufferSubData(GL_ARRAY_BUFFER, 0, (GLsizeiptr)(sizeof(float) * 3 * (size_t)m->nverts),
                          src[k]);
    }
}

void vw_glmesh_destroy(vw_glmesh *m) {
    if (!m->vao) return;
    p_glDeleteBuffers(3, m->vbo);
    p_glDeleteBuffers(1, &m->ebo);
    p_glDeleteVertexArrays(1, &m->vao);
    memset(m, 0, sizeof *m);
}

void vw_gl_begin(int w, int h) {
    p_glViewport(0, 0, w, h);
    p_glClearColor(0.12f, 0.13f, 0.15f, 1.0f);
    p_glEnable(GL_DEPTH_TEST);
    p_glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
}

void vw_gl_draw(const vw_glmesh *m, const float vp[16], const float off[3]) {
    p_glUseProgram(mesh_prog);
    p_glUniformMatrix4fv(loc_vp, 1, GL_FALSE, vp);
    p_glUniform3fv(loc_off, 1, off);
    p_glBindVertexArray(m->vao);
    p_glDrawElements(GL_TRIANGLES, 3 * m->ntris, GL_UNSIGNED_INT, NULL);
    p_glBindVertexArray(0);
}

void vw_gl_lines(const float *pos, const float *col, int32_t nverts, const float vp[16],
                 const float off[3]) {
    if (nverts < 2) return;
    /* the mesh shader, with every normal towards its light: the colours come out unshaded */
    const int grow = (size_t)nverts > line_cap;
    if (grow) {
        float *nrm = realloc(line_nrm, sizeof(float) * 3 * (size_t)nverts);
        if (!nrm) return;
        line_nrm = nrm;
        for (int32_t v = 0; v < nverts; ++v)
            nrm[3 * v] = 0.3f, nrm[3 * v + 1] = 0.8f, nrm[3 * v + 2] = 0.6f;
    }
    const float *src[3] = {pos, line_nrm, col};
    const GLsizeiptr bytes = (GLsizeiptr)(sizeof(float) * 3 * (size_t)nverts);
    p_glBindVertexArray(line_vao);
    for (int k = 0; k < 3; ++k) {
        p_glBindBuffer(GL_ARRAY_BUFFER, line_vbo[k]);
        if (grow)
            p_glBufferData(GL_ARRAY_BUFFER, bytes, src[k], GL_STREAM_DRAW);
        else
            p_glBufferSubData(GL_ARRAY_BUFFER, 0, bytes, src[k]);
    }
    if (grow) line_cap = (size_t)nverts;
    p_glUseProgram(mesh_prog);
    p_glUniformMatrix4fv(loc_vp, 1, GL_FALSE, vp);
    p_glUniform3fv(loc_off, 1, off);
    /* over everything: a contact inside the flesh or behind a collider is still seen */
    p_glDisable(GL_DEPTH_TEST);
    p_glDrawArrays(GL_LINES, 0, nverts & ~1);
    p_glEnable(GL_DEPTH_TEST);
    p_glBindVertexArray(0);
}

void vw_gl_hud(const uint8_t *rgb, int w, int h, int fb_w, int fb_h) {
    p_glDisable(GL_DEPTH_TEST);
    p_glUseProgram(hud_prog);
    p_glBindTexture(GL_TEXTURE_2D, hud_tex);
    p_glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    p_glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, w, h, 0, GL_RGB, GL_UNSIGNED_BYTE, rgb);
    p_glUniform1i(loc_tex, 0);
    const float rect[4] = {-1.0f, 1.0f - 2.0f * h / fb_h, 2.0f * w / fb_w, 2.0f * h / fb_h};
    p_glUniform4fv(loc_rect, 1, rect);
    p_glBindVertexArray(hud_vao);
    p_glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    p_glBindVertexArray(0);
    p_glEnable(GL_DEPTH_TEST);
}

void vw_gl_read(int w, int h, uint8_t *rgb) {
    p_glPixelStorei(GL_PACK_ALIGNMENT, 1);
    p_glReadBuffer(GL_BACK);
    p_glReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, rgb);
    size_t row = 3 * (size_t)w; /* GL's rows run bottom up */
    uint8_t *tmp = malloc(row);
    for (int y = 0; tmp && y < h / 2; ++y) {
        memcpy(tmp, rgb + row * y, row);
        memcpy(rgb + row * y, rgb + row * (h - 1 - y), row);
        memcpy(rgb + row * (h - 1 - y), tmp, row);
    }
    free(tmp);
}

void vw_gl_finish(void) {
    p_glFinish();
}
