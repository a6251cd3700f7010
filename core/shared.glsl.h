/* veil — definitions shared by C and GLSL: binding slots, limits and the
 * per-sample physics, so that the CPU tests exercise the same formulas as
 * the shaders. Included by C code as a header, and prepended to every
 * shader (after `#version 450` and `#define VEIL_GLSL 1`).
 *
 * Only scalar functions live here (C has no vec3); each is written once
 * with the VEIL_* portability macros below.
 */
#ifndef VEIL_SHARED_GLSL_H
#define VEIL_SHARED_GLSL_H

#ifdef VEIL_GLSL
#define VEIL_FN
#define VEIL_PRECISE precise
#define VEIL_EXPF exp
#define VEIL_POWF pow
#define VEIL_SQRTF sqrt
#define VEIL_ABSF abs
#define VEIL_FLOORF floor
#define VEIL_MINF min
#define VEIL_MAXF max
#define VEIL_FLOAT(x) float(x)
#define VEIL_INT(x) int(x)
/* std140 blocks: only 16-byte members, so C and GLSL lay them out alike */
#define VEIL_V4(name) vec4 name
#define VEIL_IV4(name) ivec4 name
#define VEIL_UV4(name) uvec4 name
#define VEIL_STRUCT_BEGIN(name) struct name {
#define VEIL_STRUCT_END(name) };
#else
#include <math.h>
#include <stdbool.h> /* GLSL's bool, used by the shared schemes (propagate/opv_schemes.glsl.h) */
#define VEIL_FN static inline
#define VEIL_PRECISE /* C is compiled with -ffp-contract=off */
#define VEIL_EXPF expf
#define VEIL_POWF powf
#define VEIL_SQRTF sqrtf
#define VEIL_ABSF fabsf
#define VEIL_FLOORF floorf
#define VEIL_MINF fminf
#define VEIL_MAXF fmaxf
#define VEIL_FLOAT(x) ((float)(x))
#define VEIL_INT(x) ((int)(x))
#include <stdint.h>
#define VEIL_V4(name) float name[4]
#define VEIL_IV4(name) int32_t name[4]
#define VEIL_UV4(name) uint32_t name[4]
#define VEIL_STRUCT_BEGIN(name) typedef struct name {
#define VEIL_STRUCT_END(name) } name;
#endif

#define VEIL_PI 3.14159265358979323846

/* A Gaussian particle is cut where it falls below this fraction of its peak
 * (see volume/rbf.h for the mass this drops: 3.6e-4 of the particle). */
#define VEIL_RBF_CUTOFF 1e-4

/* Edge of a cubic brick of voxels: the unit of particle binning for the
 * splat, and the compute work group of the inject and propagate passes
 * (8^3 = 512 invocations, under GL's guaranteed minimum of 1024). */
#define VEIL_BRICK 8

/* Lights: four share one RGBA optical-depth texture. */
#define VEIL_MAX_LIGHTS 16
#define VEIL_MAX_OPV_TEXTURES (VEIL_MAX_LIGHTS / 4)
#define VEIL_LIGHT_POINT 0
#define VEIL_LIGHT_DIRECTIONAL 1
#define VEIL_LIGHT_SPOT 2

/* Work groups, declared once for the shaders' local_size and the C code
 * that dispatches them. The ray marcher: 8x8 pixels. The occupancy pass:
 * 4^3 bricks. The ordered optical-depth sweep: 128 voxels of one shell or
 * slice in a row. */
#define VEIL_MARCH_GROUP 8
#define VEIL_OCCUPANCY_GROUP 4
#define VEIL_SWEEP_GROUP 128

/* Outside the extinction volume the marcher's steps through fog grow with
 * the distance travelled: this fraction of it (fog and light vary on the
 * scale of the distance from the camera far away; the closed-form fog
 * integral keeps each step's transmittance exact whatever its length). */
#define VEIL_FOG_STEP_FRACTION 0.02

/* At most this many exponential fogs (each is evaluated in closed form per
 * sample, in the marcher). */
#define VEIL_MAX_FOGS 4

/* Rays stop when every channel's transmittance is below this: what is
 * dropped is at most this fraction of the light behind (the attenuated
 * background is still added with the transmittance reached). */
#define VEIL_MIN_TRANSMITTANCE 1e-4

/* Binding points. */
#define VEIL_BIND_PARTICLES 0   /* SSBO: vec4 centre+amplitude, sharpness */
#define VEIL_BIND_BRICK_START 1 /* SSBO: uint offsets per brick (+1) */
#define VEIL_BIND_BRICK_LIST 2  /* SSBO: particle indices */
#define VEIL_BIND_FLAGS 3       /* SSBO: uint "changed" flag of a Jacobi step */
#define VEIL_BIND_FACES 4       /* SSBO: the faces of one sweep shell */
#define VEIL_IMAGE_EV 0         /* image unit: r32f extinction (density) volume */
#define VEIL_IMAGE_OPV_SRC 1    /* image unit: rgba32f optical depth, read */
#define VEIL_IMAGE_OPV_DST 2    /* image unit: rgba32f optical depth, written */
#define VEIL_IMAGE_OUT 3        /* image unit: rgba32f output image (march: radiance, alpha) */
#define VEIL_IMAGE_AOV_T 4      /* image unit: rgba32f march AOV: transmittance rgb, P */
#define VEIL_IMAGE_AOV_S 5      /* image unit: rgba32f march AOV: single scattering rgb, depth */
#define VEIL_UBO_MARCH 0        /* uniform block: veil_march_block */
#define VEIL_TEX_EV 0           /* texture unit: sampled EV */
#define VEIL_TEX_OPV0 1         /* texture units 1..4: sampled OPVs */
#define VEIL_TEX_OCC 5          /* texture unit: occupancy bricks (max density per brick) */

/* A light as the GPU sees it: one shape for every shader (std140, 48 bytes).
 * Filled from scene/scene.h's veil_light by veil_gpu_light_from(). */
VEIL_STRUCT_BEGIN(veil_gpu_light)
    VEIL_V4(position);  /* xyz: point, spot position (m); w: type, VEIL_LIGHT_* */
    VEIL_V4(direction); /* xyz: directional: unit travel direction; spot: its axis; w: spot cos(inner angle) */
    VEIL_V4(color);     /* rgb: W/sr (point, spot) or W/m^2 (directional); w: spot cos(outer angle) */
VEIL_STRUCT_END(veil_gpu_light)

/* An exponential fog: density * exp(-falloff <x - origin, direction>) in its box. */
VEIL_STRUCT_BEGIN(veil_gpu_fog)
    VEIL_V4(direction); /* xyz: unit n; w: density at the origin plane */
    VEIL_V4(origin);    /* xyz: m; w: falloff (m^-1) */
    VEIL_V4(box_min);   /* xyz: m */
    VEIL_V4(box_max);   /* xyz: m */
VEIL_STRUCT_END(veil_gpu_fog)

/* Everything the ray marcher (render/shaders/march.comp) reads besides its
 * textures, in one std140 uniform block at VEIL_UBO_MARCH. */
VEIL_STRUCT_BEGIN(veil_march_block)
    VEIL_V4(cam_pos);      /* xyz: camera position (m) */
    VEIL_V4(cam_fwd);      /* xyz: unit view direction */
    VEIL_V4(cam_right);    /* xyz: right, scaled by tan(fov/2) and the aspect */
    VEIL_V4(cam_up);       /* xyz: up, scaled by tan(fov/2) */
    VEIL_V4(box_min);      /* xyz: the EV's medium, first voxel centre (m) */
    VEIL_V4(box_max);      /* xyz: last voxel centre (m) */
    VEIL_V4(tex_min);      /* xyz: texture coordinates are (x - tex_min) * tex_inv_size */
    VEIL_V4(tex_inv_size); /* xyz: m^-1 */
    VEIL_V4(sigma_t);      /* rgb: m^-1 per unit density */
    VEIL_V4(sigma_s);      /* rgb: m^-1 per unit density */
    VEIL_V4(background);   /* rgb: radiance behind the medium */
    VEIL_V4(march);        /* x: step (m), y: floor on |S - X|^2 (m^2), z: voxel (m), w: HG g */
    VEIL_V4(limits);       /* x: no step starts at or beyond this distance (m; 3e38: no limit) */
    VEIL_IV4(size);        /* x, y: image size (pixels); z: lights; w: fogs */
    VEIL_UV4(flags);       /* x: has a volume, y: skip empty bricks, z: jitter seed */
    veil_gpu_light lights[VEIL_MAX_LIGHTS];
    veil_gpu_fog fogs[VEIL_MAX_FOGS];
VEIL_STRUCT_END(veil_march_block)

/* Henyey–Greenstein phase function (sr^-1), cos_theta the cosine between the
 * light's travel direction and the scattered direction; g = 0 is isotropic
 * 1/(4 pi). The denominator is >= (1-|g|)^2 > 0 for |g| < 1. */
VEIL_FN float veil_phase_hg(float cos_theta, float g)
{
    float denom = 1.0 + g * g - 2.0 * g * cos_theta;
    return VEIL_FLOAT((1.0 - g * g) / (4.0 * VEIL_PI)) / (denom * VEIL_SQRTF(denom));
}

/* A spot light's intensity factor at angle theta from its axis, given
 * cos(theta): 1 inside the inner cone, 0 outside the outer cone, and a
 * smoothstep in cos(theta) between (C1, monotonic). cos_outer < cos_inner. */
VEIL_FN float veil_spot_falloff(float cos_theta, float cos_inner, float cos_outer)
{
    if (cos_theta >= cos_inner) return 1.0;
    if (cos_theta <= cos_outer) return 0.0;
    float t = (cos_theta - cos_outer) / (cos_inner - cos_outer);
    return t * t * (3.0 - 2.0 * t);
}

/* (1 - exp(-x)) / x for x >= 0: the fraction of a step of optical thickness
 * x that in-scattered light survives, integrated over the step. Below 0.1 a
 * 4-term series (truncation x^4/120 < 1e-6 relative), above it the direct
 * form, whose cancellation error is ~eps/x < 1e-6. */
VEIL_FN float veil_step_integral(float x)
{
    if (x < 0.1) return 1.0 - x * (0.5 - x * (1.0 / 6.0 - x * (1.0 / 24.0)));
    return (1.0 - VEIL_EXPF(-x)) / x;
}

/* Exponential fog, density rho0 * exp(-k) with k linear along a segment of
 * length len from k0 to k1 (k = falloff * <x - origin, n>): the integral is
 *   rho0 * len * exp(-min(k0, k1)) * (1 - exp(-|k1 - k0|)) / |k1 - k0|,
 * which has no cancellation as k1 - k0 -> 0 (the series of
 * veil_step_integral) and no overflow for large |k1 - k0| (the exponential
 * is taken at the denser end only). The density there is capped at
 * rho0 * exp(VEIL_FOG_MAX_EXPONENT): fog that dense is opaque anyway. */
#define VEIL_FOG_MAX_EXPONENT 60.0
VEIL_FN float veil_exp_fog_integral(float rho0, float k0, float k1, float len)
{
    float kmin = VEIL_MAXF(VEIL_MINF(k0, k1), VEIL_FLOAT(-VEIL_FOG_MAX_EXPONENT));
    return rho0 * len * VEIL_EXPF(-kmin) * veil_step_integral(VEIL_ABSF(k1 - k0));
}

#endif
