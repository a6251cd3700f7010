/* Alpha and transmittance held in [0, 1] where rounding can cross them (issue 42).
 *
 * On an NVIDIA H200 every empty pixel had T = 1 + 2^-23 and alpha = -2.98e-8: the GPU's exp is an
 * approximate exp2, and exp(-x) of a tiny x >= 0 rounds up to 1 + 1 ulp. llvmpipe's exp is exact
 * enough never to do so, so this test forces the crossing: a negative thickness -x stands in for the
 * GPU's rounding (exp(+x) > 1 on any device), and transmittances of 1 + k ulp stand in for what a
 * rounded exp or a rounded 1/3 leaves. Checked on the GPU (core/shared.glsl.h, the functions the
 * march's every step and its output use) and in C (the same source):
 *  - a ray of 256 steps of the same thickness: T <= 1 whatever the step's exp gives, and for x >= 0
 *    within a relative 256 * 2^-21 of exp(-256 x) (each step's product rounds by 2^-24 relative,
 *    the step's exp by at most 2 ulp on llvmpipe, 2^-22 relative: 256 steps accumulate under
 *    256 * (2^-24 + 2^-22) < 256 * 2^-21);
 *  - alpha of T = 1 + k ulp (k = 0..4) in all three channels is exactly 0, of T = 0 exactly 1, and of
 *    any T in [0, 1 + 4 ulp] in [0, 1] and within 2^-22 of 1 - mean(T) clamped;
 *  - a rendered frame of a medium that covers part of the view: every pixel's alpha and T in [0, 1],
 *    alpha exactly 0 where the ray meets no medium (T exactly 1 there). */
#include <epoxy/gl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "core/shared.glsl.h"
#include "frame/renderer.h"
#include "gpu/gl_util.h"
#include "io/scene.h"
#include "render/image_set.h"

static const char* const SHADER =
    "layout(local_size_x = 64) in;\n"
    "layout(std430, binding = 0) readonly buffer a_in { vec4 xs[]; };\n"
    "layout(std430, binding = 1) writeonly buffer a_out { vec4 ys[]; };\n"
    "void main()\n"
    "{\n"
    "    uint i = gl_GlobalInvocationID.x;\n"
    "    if (i >= uint(xs.length())) return;\n"
    "    vec4 x = xs[i];\n"
    "    if (x.w == 0.0) { // a ray of 256 steps of thickness x.xyz\n"
    "        vec3 T = vec3(1.0);\n"
    "        for (int k = 0; k < 256; ++k)\n"
    "            T *= vec3(veil_step_transmittance(x.x), veil_step_transmittance(x.y), veil_step_transmittance(x.z));\n"
    "        ys[i] = vec4(T, veil_alpha(T.r, T.g, T.b));\n"
    "    } else { // alpha of the transmittance x.xyz\n"
    "        ys[i] = vec4(x.xyz, veil_alpha(x.x, x.y, x.z));\n"
    "    }\n"
    "}\n";

#define RAYS 12
#define ALPHAS 8
#define N (RAYS + ALPHAS)

static void inputs(float in[N][4])
{
    const float ulp = ldexpf(1.0f, -23), x[RAYS] = {0.0f, 1e-9f, 1e-7f, 1e-4f, 0.01f, 0.3f, -ldexpf(1.0f, -24),
                                                    -ldexpf(1.0f, -23), -1e-7f, -1e-6f, -1e-4f, -0.01f};
    for (int i = 0; i < RAYS; ++i) in[i][0] = in[i][1] = in[i][2] = x[i], in[i][3] = 0.0f;
    in[2][1] = 0.02f, in[8][2] = 0.05f; /* channels that differ */
    for (int k = 0; k <= 4; ++k) { /* T = 1 + k ulp in every channel */
        float t = 1.0f + (float)k * ulp;
        in[RAYS + k][0] = in[RAYS + k][1] = in[RAYS + k][2] = t, in[RAYS + k][3] = 1.0f;
    }
    const float mixed[3][3] = {{1.0f + 4 * ulp, 1.0f, 1.0f - ulp}, {0.0f, 0.0f, 0.0f}, {0.25f, 1.0f + 2 * ulp, 0.5f}};
    for (int k = 0; k < 3; ++k)
        for (int c = 0; c < 3; ++c) in[RAYS + 5 + k][c] = mixed[k][c], in[RAYS + 5 + k][3] = 1.0f;
}

/* The checks of one side's results (GPU or C) for the inputs. */
static void check_results(const char* side, const float in[N][4], const float out[N][4])
{
    for (int i = 0; i < RAYS; ++i) {
        for (int c = 0; c < 3; ++c) {
            CHECK(out[i][c] <= 1.0f && out[i][c] >= 0.0f, "%s: a ray of 256 steps of %g: T = %.9g", side,
                  (double)in[i][c], (double)out[i][c]);
            if (in[i][c] >= 0.0f) {
                const double want = exp(-256.0 * (double)in[i][c]);
                CHECK(fabs(out[i][c] - want) <= 256.0 * ldexp(1.0, -21) * want, "%s: 256 steps of %g: T %.9g, exp %.9g",
                      side, (double)in[i][c], (double)out[i][c], want);
            } else {
                CHECK(out[i][c] == 1.0f, "%s: a step's exp over 1 (thickness %g) held at 1: T %.9g", side,
                      (double)in[i][c], (double)out[i][c]);
            }
        }
        CHECK(out[i][3] >= 0.0f && out[i][3] <= 1.0f, "%s: ray %d: alpha %.9g", side, i, (double)out[i][3]);
    }
    for (int i = RAYS; i < N; ++i) {
        const float* t = in[i];
        const double a = out[i][3], m = fmin(fmax(1.0 - ((double)t[0] + t[1] + t[2]) / 3.0, 0.0), 1.0);
        CHECK(a >= 0.0 && a <= 1.0, "%s: alpha of T (%.9g, %.9g, %.9g) = %.9g", side, (double)t[0], (double)t[1],
              (double)t[2], a);
        CHECK(fabs(a - m) <= ldexp(1.0, -22), "%s: alpha %.9g of T (%.9g, %.9g, %.9g), want %.9g", side, a,
              (double)t[0], (double)t[1], (double)t[2], m);
        if (t[0] >= 1.0f && t[1] >= 1.0f && t[2] >= 1.0f) CHECK(a == 0.0, "%s: alpha %.9g of T >= 1: not 0", side, a);
        if (t[0] == 0.0f && t[1] == 0.0f && t[2] == 0.0f) CHECK(a == 1.0, "%s: alpha %.9g of T = 0: not 1", side, a);
    }
}

static void check_frame(const veil_gl* gl)
{
    static const char* const scene_json =
        "{\"camera\": {\"position\": [0, 0, 4], \"look_at\": [0, 0, 0], \"width\": 64, \"height\": 48},"
        " \"medium\": {\"sigma_s\": [2, 2, 2], \"sigma_a\": [0.1, 0.2, 0.3], \"sources\": [{\"type\": \"rbf\","
        " \"particles\": [{\"center\": [0, 0, 0], \"amplitude\": 1.5, \"sharpness\": 3},"
        " {\"center\": [0.4, 0.1, 0], \"amplitude\": 0.8, \"sharpness\": 5}]}]},"
        " \"lights\": [{\"type\": \"directional\", \"direction\": [0, -1, 0], \"irradiance\": [1, 1, 1]}],"
        " \"background\": {\"color\": [0.1, 0.2, 0.3]}}";
    veil_error err = {0};
    veil_scene s;
    veil_result r = veil_scene_parse("alpha_bounds.json", scene_json, strlen(scene_json), &s, &err);
    CHECK(r == VEIL_OK, "the scene: %s", err.msg);
    if (r != VEIL_OK) return;
    veil_renderer* ren = NULL;
    veil_image_set im = {0};
    r = veil_renderer_create(gl, &ren, &err);
    if (r == VEIL_OK) r = veil_render_scene_images(ren, &s, &(veil_render_opts){0}, &im, NULL, &err);
    CHECK(r == VEIL_OK, "the frame: %s", err.msg);
    int empty = 0, covered = 0;
    for (int i = 0; r == VEIL_OK && i < im.width * im.height; ++i) {
        const float a = im.rgba[4 * i + 3], *T = im.aov_t + 4 * i;
        CHECK(a >= 0.0f && a <= 1.0f, "pixel %d: alpha %.9g", i, (double)a);
        for (int c = 0; c < 3; ++c) CHECK(T[c] >= 0.0f && T[c] <= 1.0f, "pixel %d: T[%d] %.9g", i, c, (double)T[c]);
        if (T[3] == 0.0f) { /* P = 0: the ray met no density */
            ++empty;
            CHECK(a == 0.0f && T[0] == 1.0f && T[1] == 1.0f && T[2] == 1.0f, "pixel %d meets no medium: alpha %.9g, T "
                  "(%.9g, %.9g, %.9g)", i, (double)a, (double)T[0], (double)T[1], (double)T[2]);
        } else {
            covered += a > 0.01f;
        }
    }
    CHECK(empty > 100 && covered > 100, "the frame has %d empty and %d covered pixels: the test needs both", empty, covered);
    veil_image_set_free(&im);
    veil_renderer_destroy(ren);
    veil_scene_free(&s);
}

int main(void)
{
    float in[N][4], out[N][4];
    inputs(in);
    /* C: the same functions */
    for (int i = 0; i < N; ++i) {
        if (in[i][3] == 0.0f) {
            float T[3] = {1.0f, 1.0f, 1.0f};
            for (int k = 0; k < 256; ++k)
                for (int c = 0; c < 3; ++c) T[c] *= veil_step_transmittance(in[i][c]);
            out[i][0] = T[0], out[i][1] = T[1], out[i][2] = T[2], out[i][3] = veil_alpha(T[0], T[1], T[2]);
        } else {
            memcpy(out[i], in[i], sizeof out[i]);
            out[i][3] = veil_alpha(in[i][0], in[i][1], in[i][2]);
        }
    }
    check_results("C", (const float(*)[4])in, (const float(*)[4])out);

    veil_gl* gl = check_gpu_or_skip();
    veil_error err = {0};
    GLuint prog = 0, bufs[2] = {0, 0};
    CHECK(veil_gl_compute_program("test_alpha_bounds", SHADER, &prog, &err) == VEIL_OK, "%s", err.msg);
    CHECK(veil_gl_buffer(in, sizeof in, GL_DYNAMIC_STORAGE_BIT, "test inputs", &bufs[0], &err) == VEIL_OK, "%s", err.msg);
    CHECK(veil_gl_buffer(NULL, sizeof out, GL_DYNAMIC_STORAGE_BIT, "test outputs", &bufs[1], &err) == VEIL_OK, "%s",
          err.msg);
    if (prog && bufs[0] && bufs[1]) {
        glUseProgram(prog);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, bufs[0]);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, bufs[1]);
        glDispatchCompute(1, 1, 1);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        memset(out, 0, sizeof out);
        glGetNamedBufferSubData(bufs[1], 0, sizeof out, out);
        CHECK(glGetError() == GL_NO_ERROR, "%s", "a GL error");
        check_results("GPU", (const float(*)[4])in, (const float(*)[4])out);
        glUseProgram(0);
    }
    glDeleteBuffers(2, bufs);
    glDeleteProgram(prog);
    check_frame(gl);
    veil_gl_destroy(gl);
    return check_finish();
}
