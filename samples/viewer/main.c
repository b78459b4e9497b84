/* sinew-view: plays a baked character in a window, the way an engine would host sinew:
 * the engine imports the asset and samples its clips itself, hands sinew each frame's
 * bone transforms and draws the surface sinew gives back, next to the plain skinning it
 * would have drawn without it. Fixed simulation steps under a variable render rate; with
 * --frames the clock advances one render interval a frame, so runs, screenshots and
 * recordings are reproducible whatever the machine's speed. */
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "app.h"

static double now_s(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void on_key(GLFWwindow *w, int key, int scancode, int action, int mods) {
    (void)scancode, (void)mods;
    if (action != GLFW_PRESS) return;
    vw_app *app = glfwGetWindowUserPointer(w);
    if (key == GLFW_KEY_ESCAPE || key == GLFW_KEY_Q) glfwSetWindowShouldClose(w, 1);
    char c = key == GLFW_KEY_SPACE                    ? ' '
             : key == GLFW_KEY_PERIOD                 ? '.'
             : key >= GLFW_KEY_A && key <= GLFW_KEY_Z ? (char)('a' + key - GLFW_KEY_A)
             : key >= GLFW_KEY_0 && key <= GLFW_KEY_9 ? (char)('0' + key - GLFW_KEY_0)
                                                      : 0;
    if (c) vw_app_key(app, c);
}

static void mouse_at(GLFWwindow *w, double *x, double *y) {
    int ww, wh;
    glfwGetCursorPos(w, x, y);
    glfwGetWindowSize(w, &ww, &wh);
    *x = ww > 0 ? fmin(1, fmax(0, *x / ww)) : 0, *y = wh > 0 ? fmin(1, fmax(0, *y / wh)) : 0;
}

static void on_button(GLFWwindow *w, int button, int action, int mods) {
    (void)mods;
    if (button != GLFW_MOUSE_BUTTON_LEFT) return;
    vw_app *app = glfwGetWindowUserPointer(w);
    double x, y;
    mouse_at(w, &x, &y);
    if (action == GLFW_PRESS) vw_poke_press(app, (float)x, (float)y);
    if (action == GLFW_RELEASE) vw_poke_release(app);
}

static void on_cursor(GLFWwindow *w, double cx, double cy) {
    (void)cx, (void)cy;
    vw_app *app = glfwGetWindowUserPointer(w);
    double x, y;
    mouse_at(w, &x, &y);
    vw_poke_move(app, (float)x, (float)y);
}

/* Steps due this frame: the accumulator holds simulated time not yet stepped; a frame
 * that falls far behind drops time rather than spiral (at most 4 steps a frame). */
static double advance(vw_app *app, double frame_dt) {
    double t0 = now_s();
    if (!app->paused) app->acc += frame_dt * (app->slow ? 0.25 : 1.0);
    int n = 0;
    while (app->acc >= app->step_dt - 1e-9 && n < 4) {
        app->sim_t += app->step_dt;
        if (app->world.world) vw_world_move(&app->world, app->sim_t);
        vw_sim_step(&app->sim, app->sim_t, (float)app->step_dt);
        app->acc -= app->step_dt, n++, app->steps++;
    }
    if (n == 4) app->acc = 0;
    if (app->single) {
        app->sim_t += app->step_dt;
        if (app->world.world) vw_world_move(&app->world, app->sim_t);
        vw_sim_step(&app->sim, app->sim_t, (float)app->step_dt);
        app->single = 0, n++, app->steps++;
    }
    app->steps_this_frame = n;
    const uint32_t wc = app->sim.ch[0].stats.world_contacts;
    if (wc > app->contacts_max) app->contacts_max = wc;
    if (wc && app->first_contact_s < 0) app->first_contact_s = app->sim_t;
    return n ? 1000 * (now_s() - t0) : 0;
}

static int run(vw_app *app, GLFWwindow *win) {
    double last = now_s(), clock = 0, start = last;
    int64_t frame = 0;
    int ok = 1;
    while (!glfwWindowShouldClose(win) && ok) {
        double t = now_s(), wall_dt = t - last;
        last = t;
        double frame_dt = app->opt.frames ? 1.0 / app->opt.render_hz : wall_dt;
        clock += frame_dt;
        vw_app_script(app, clock);
        if (app->reinit && !(ok = vw_app_reinit(app))) break;
        double step_ms = advance(app, frame_dt);
        vw_sim_flush(&app->sim); /* the recording's writes, between frames */
        double r0 = now_s();
        vw_debug_collect(app);
        int fb_w, fb_h;
        glfwGetFramebufferSize(win, &fb_w, &fb_h);
        vw_app_draw(app, fb_w, fb_h, wall_dt * 1000, step_ms);
        int last_frame = app->opt.frames && frame + 1 >= app->opt.frames;
        if (app->opt.record || (last_frame && app->opt.screenshot))
            ok = vw_app_capture(app, fb_w, fb_h, last_frame);
        vw_gl_finish(); /* so the render time is the GPU's too, not just the queueing */
        double render_ms = 1000 * (now_s() - r0);
        glfwSwapBuffers(win);
        glfwPollEvents();
        if (app->steps_this_frame) app->step_ms_sum += step_ms, app->step_frames++;
        app->render_ms_sum += render_ms;
        app->last_render_ms = render_ms;
        frame++;
        if (last_frame) break;
    }
    app->frames = frame;
    app->wall_s = now_s() - start;
    return ok;
}

int main(int argc, char **argv) {
    vw_app app;
    int rc = vw_app_parse(&app, argc, argv);
    if (rc >= 0) return rc;
    char err[512] = "";
    if (!vw_app_load(&app, err, sizeof err)) {
        fprintf(stderr, "sinew-view: %s\n", err);
        vw_app_free(&app);
        return 1;
    }
    if (!glfwInit()) {
        fprintf(stderr, "sinew-view: no display: GLFW cannot start (run under xvfb-run "
                        "for an offscreen session)\n");
        vw_app_free(&app);
        return 1;
    }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_RESIZABLE, app.opt.frames ? GLFW_FALSE : GLFW_TRUE);
    GLFWwindow *win = glfwCreateWindow(app.opt.width, app.opt.height, "sinew-view", NULL, NULL);
    if (!win) {
        fprintf(stderr, "sinew-view: cannot open a window with an OpenGL 3.3 core context\n");
        glfwTerminate();
        vw_app_free(&app);
        return 1;
    }
    glfwMakeContextCurrent(win);
    /* vsync for watching; none offscreen, where the frame rate is what is measured */
    glfwSwapInterval(app.opt.frames ? 0 : 1);
    glfwSetWindowUserPointer(win, &app);
    glfwSetKeyCallback(win, on_key);
    glfwSetMouseButtonCallback(win, on_button);
    glfwSetCursorPosCallback(win, on_cursor);
    app.window = win;
    int ok = vw_gl_init(err, sizeof err) && vw_app_gl_setup(&app, err, sizeof err);
    if (!ok) fprintf(stderr, "sinew-view: %s\n", err);
    if (ok) ok = run(&app, win);
    if (ok && app.opt.json) vw_app_print_json(&app);
    vw_app_free(&app);
    vw_gl_shutdown();
    glfwDestroyWindow(win);
    glfwTerminate();
    return ok ? 0 : 1;
}
