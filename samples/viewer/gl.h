/* The viewer's drawing: OpenGL 3.3 core through a loader of its own (glfwGetProcAddress),
 * lit triangle meshes with per-vertex colours and a bitmap HUD. */
#ifndef SW_VIEWER_GL_H
#define SW_VIEWER_GL_H

#include <stdint.h>

typedef struct vw_glmesh {
    unsigned vao, vbo[3], ebo;
    int32_t nverts, ntris;
} vw_glmesh;

/* Loads the GL functions (a current context is needed) and builds the shaders; 0 and a
 * message in err when the context lacks something. */
int vw_gl_init(char *err, size_t errlen);
void vw_gl_shutdown(void);

int vw_glmesh_create(vw_glmesh *m, int32_t nverts, const uint32_t *tris, int32_t ntris);
void vw_glmesh_update(vw_glmesh *m, const float *pos, const float *nrm, const float *col);
void vw_glmesh_destroy(vw_glmesh *m);

/* Clears the w x h frame to the background. */
void vw_gl_begin(int w, int h);
/* Draws m with the column-major view-projection vp, shifted by off. */
void vw_gl_draw(const vw_glmesh *m, const float vp[16], const float off[3]);
/* Draws line segments (vertices 2k, 2k + 1; per-vertex colours, unlit) with vp, shifted by
 * off, over what is drawn (no depth test). */
void vw_gl_lines(const float *pos, const float *col, int32_t nverts, const float vp[16],
                 const float off[3]);
/* Draws an RGB image (top row first) at the top-left of the frame; black is transparent. */
void vw_gl_hud(const uint8_t *rgb, int w, int h, int fb_w, int fb_h);
/* Reads the frame into rgb (top row first). */
void vw_gl_read(int w, int h, uint8_t *rgb);
void vw_gl_finish(void);

#endif
