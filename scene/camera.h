/* veil — the pinhole camera: position, look-at point, up vector and
 * field of view along its sensor fit, with a lens shift and clip planes.
 * Pixel (px, py), py = 0 the top row, looks along
 * normalize(center + sx * right + sy * up) with sx = 2 (px + 0.5) / W - 1
 * and sy = 1 - 2 (py + 0.5) / H, where right and up are scaled by
 * tan(fov_x / 2) and tan(fov_y / 2) (one of them from the camera's fov, the
 * other by the aspect W / H), and center = fwd + shift x (fitted extent)
 * along right and up. render/shaders/march.comp uses the same formula.
 * Also the turntable's camera of frame f. */
#ifndef VEIL_CAMERA_H
#define VEIL_CAMERA_H

#include "../core/result.h"
#include "scene.h"

typedef struct veil_camera_basis {
    float pos[3], fwd[3], right[3], up[3];
    float center[3];  /* the image centre's direction: fwd, moved by the shift (rays go through
                         center + sx right + sy up) */
    float offset[2];  /* the shift at unit distance along fwd, in right's and up's unit directions */
    float clip[2];    /* near, far along fwd (m); far INFINITY when the camera has none */
} veil_camera_basis;

/* tan of half the field of view across the width (*tx) and the height
 * (*ty) of a width x height image, from the camera's fov and sensor fit. */
void veil_camera_tan_half(const veil_camera* c, int width, int height, double* tx, double* ty);

veil_result veil_camera_make_basis(const veil_camera* c, int width, int height, veil_camera_basis* out,
                                   veil_error* err);
/* The camera turned by `angle` radians about its up axis through look_at:
 * the position moves on a circle, look_at, up and the lens stay. */
veil_camera veil_camera_orbit(const veil_camera* c, double angle);

/* The camera of frame f (0-based) of an n-frame turntable: one full turn in
 * n equal steps, frame 0 the scene's own camera. A pure function of
 * (c, f, n): any process rendering frame f sees the same camera. */
veil_camera veil_camera_of_frame(const veil_camera* c, long frame, long frames);

void veil_camera_ray(const veil_camera_basis* b, int width, int height, int px, int py, float dir[3]);

/* The camera as OpenEXR's header matrices (io/image.h, veil_exr_meta; row
 * vectors, row-major): worldToCamera into x right, y up, z the viewing
 * direction; worldToNDC onto the image, (0, 0) its top-left corner and
 * (1, 1) its bottom-right, after dividing by w (= the depth along z), with
 * the pixel centres where veil_camera_ray shoots. */
void veil_camera_exr_matrices(const veil_camera_basis* b, float world_to_camera[16], float world_to_ndc[16]);

#endif
