#include "camera.h"

#include <cglm/cglm.h>
#include <math.h>

veil_result veil_camera_make_basis(const veil_camera* c, int width, int height, veil_camera_basis* out,
                                   veil_error* err)
{
    vec3 fwd, right, up, pos, at, upv;
    glm_vec3_copy((float*)c->position, pos);
    glm_vec3_copy((float*)c->look_at, at);
    glm_vec3_copy((float*)c->up, upv);
    glm_vec3_sub(at, pos, fwd);
    if (!(glm_vec3_norm(fwd) > 0.0f))
        return veil_fail(err, VEIL_ERR_INVALID, "camera: position and look_at coincide");
    glm_vec3_normalize(fwd);
    glm_vec3_cross(fwd, upv, right);
    if (!(glm_vec3_norm(right) > 1e-6f * glm_vec3_norm(upv)))
        return veil_fail(err, VEIL_ERR_INVALID, "camera: up is parallel to the view direction");
    glm_vec3_normalize(right);
    glm_vec3_cross(right, fwd, up);
    double tx, ty;
    veil_camera_tan_half(c, width, height, &tx, &ty);
    /* the shift in units of the fitted side's extent, 2 tan(fov / 2) at unit distance (Blender's) */
    double extent = 2.0 * tan(c->fov_y_deg * (VEIL_PI / 360.0));
    out->offset[0] = (float)(c->shift[0] * extent), out->offset[1] = (float)(c->shift[1] * extent);
    for (int a = 0; a < 3; ++a)
        out->center[a] = fwd[a] + out->offset[0] * right[a] + out->offset[1] * up[a]; /* right, up: unit here */
    glm_vec3_scale(right, (float)tx, right);
    glm_vec3_scale(up, (float)ty, up);
    glm_vec3_copy(pos, out->pos);
    glm_vec3_copy(fwd, out->fwd);
    glm_vec3_copy(right, out->right);
    glm_vec3_copy(up, out->up);
    out->clip[0] = c->clip[0];
    out->clip[1] = c->clip[1] > 0.0f ? c->clip[1] : INFINITY;
    return VEIL_OK;
}

void veil_camera_tan_half(const veil_camera* c, int width, int height, double* tx, double* ty)
{
    double t = tan(c->fov_y_deg * (VEIL_PI / 360.0)), aspect = (double)width / (double)height;
    int fit = c->sensor_fit;
    if (fit == VEIL_FIT_AUTO) fit = width >= height ? VEIL_FIT_HORIZONTAL : VEIL_FIT_VERTICAL;
    *tx = fit == VEIL_FIT_HORIZONTAL ? t : t * aspect;
    *ty = fit == VEIL_FIT_HORIZONTAL ? t / aspect : t;
}

void veil_camera_ray(const veil_camera_basis* b, int width, int height, int px, int py, float dir[3])
{
    float sx = 2.0f * ((float)px + 0.5f) / (float)width - 1.0f;
    float sy = 1.0f - 2.0f * ((float)py + 0.5f) / (float)height;
    float n = 0.0f;
    for (int a = 0; a < 3; ++a) {
        dir[a] = b->center[a] + sx * b->right[a] + sy * b->up[a];
        n += dir[a] * dir[a];
    }
    n = sqrtf(n);
    for (int a = 0; a < 3; ++a) dir[a] /= n;
}

veil_camera veil_camera_orbit(const veil_camera* c, double angle)
{
    veil_camera o = *c;
    double u[3], v[3], len = 0.0;
    for (int a = 0; a < 3; ++a) {
        u[a] = c->up[a];
        len += u[a] * u[a];
        v[a] = (double)c->position[a] - c->look_at[a];
    }
    len = sqrt(len);
    for (int a = 0; a < 3; ++a) u[a] /= len;
    double cs = cos(angle), sn = sin(angle), uv = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    double x[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    for (int a = 0; a < 3; ++a)
        o.position[a] = (float)(c->look_at[a] + v[a] * cs + x[a] * sn + u[a] * uv * (1.0 - cs));
    return o;
}

veil_camera veil_camera_of_frame(const veil_camera* c, long frame, long frames)
{
    return veil_camera_orbit(c, frames > 1 ? 2.0 * VEIL_PI * (double)frame / (double)frames : 0.0);
}

void veil_camera_exr_matrices(const veil_camera_basis* b, float world_to_camera[16], float world_to_ndc[16])
{
    double axis[3][3], len[3]; /* unit right, up, forward; right and up's lengths are tan(fov_x / 2), tan(fov_y / 2) */
    const float* v[3] = {b->right, b->up, b->fwd};
    for (int k = 0; k < 3; ++k) {
        len[k] = sqrt((double)v[k][0] * v[k][0] + (double)v[k][1] * v[k][1] + (double)v[k][2] * v[k][2]);
        for (int a = 0; a < 3; ++a) axis[k][a] = v[k][a] / len[k];
    }
    double wc[4][4] = {{0}}, p[4][4] = {{0}};
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) wc[i][k] = axis[k][i]; /* p_cam[k] = (p - pos) . axis[k] */
    for (int k = 0; k < 3; ++k)
        wc[3][k] = -(b->pos[0] * axis[k][0] + b->pos[1] * axis[k][1] + b->pos[2] * axis[k][2]);
    wc[3][3] = 1.0;
    /* ndc_x = 1/2 + x / (2 z tan_x), ndc_y = 1/2 - y / (2 z tan_y): X = x / (2 tan_x) + z / 2, Y = -y / (2 tan_y) + z / 2,
     * Z = 1 (ndc z = 1/depth), W = z */
    p[0][0] = 0.5 / len[0];
    p[1][1] = -0.5 / len[1];
    /* with a shift the image's centre is at (x, y) / z = offset: ndc_x = 1/2 + (x / z - off_x) / (2 tan_x) */
    p[2][0] = 0.5 - 0.5 * b->offset[0] / len[0];
    p[2][1] = 0.5 + 0.5 * b->offset[1] / len[1];
    p[2][3] = 1.0;
    p[3][2] = 1.0;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            double sum = 0.0;
            for (int k = 0; k < 4; ++k) sum += wc[i][k] * p[k][j];
            world_to_camera[4 * i + j] = (float)wc[i][j];
            world_to_ndc[4 * i + j] = (float)sum;
        }
}
