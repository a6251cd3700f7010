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
#define VEIL_LOG2F log2
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
#define VEIL_LOG2F log2f
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

/* Deep output (render/deep.h): the march compiled with VEIL_MARCH_DEEP
 * (R, the raw samples a pixel) writes each pixel's stretches of the ray to
 * two SSBOs, a band of rows at a time: the count a pixel (uint) and R
 * samples of VEIL_DEEP_SAMPLE_FLOATS floats (R, G, B, A, Z, ZBack). A stretch
 * ends where its opacity crosses a multiple of 1/R of the pixel's (equal-
 * opacity buckets), where the ray leaves the medium into empty space, and at
 * the ray's end; none opens once the mean transmittance is below
 * VEIL_DEEP_MIN_T: a sample's colour is what it adds divided by the
 * transmittance at its front, both tiny there (a float T underflows to
 * denormals near 1e-38 and to 0 below; 0/0 would be NaN), and what lies
 * behind 1e-20 is below 1e-20 of the light, so the open sample takes it. */
#define VEIL_BIND_DEEP_COUNT 5   /* SSBO: uint[band rows * width] */
#define VEIL_BIND_DEEP_SAMPLES 6 /* SSBO: float[band rows * width * R * 6] */
#define VEIL_DEEP_MIN_T 1e-20
#define VEIL_DEEP_SAMPLE_FLOATS 6 /* = VEIL_DEEP_CHANNELS (io/exr_deep.h) */

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
#define VEIL_IMAGE_AOV_V 6      /* image unit: rgba32f march AOV: volumetric multiple scattering rgb */
#define VEIL_IMAGE_AOV_Q 7      /* image unit: rgba32f march AOV: single scattering's out-scattered rgb, its P */
#define VEIL_UBO_MARCH 0        /* uniform block: veil_march_block */
#define VEIL_UBO_PROPAGATE 4    /* uniform block: the optical-depth pass's own (propagate/opv_blocks.glsl.h) */
#define VEIL_UBO_MEDIUM 6       /* uniform block: veil_medium_block (the march and the volumetric stage) */
#define VEIL_TEX_EV 0           /* texture unit: sampled EV */
#define VEIL_TEX_OPV0 1         /* texture units 1..4: sampled OPVs */
#define VEIL_TEX_OCC 5          /* texture unit: occupancy bricks (max density per brick) */
#define VEIL_TEX_LIMIT 6        /* texture unit: r32f per-pixel distance where the ray ends (veil fog) */
#define VEIL_TEX_DIFFUSION 7    /* texture unit: rgba32f multiply scattered fluence (volumetric/volumetric.h) */
#define VEIL_TEX_EMISSION 8     /* texture unit: rgba32f emission eps (W m^-3 sr^-1) on the EV's grid */
/* Texture units 9..12: r32f optical depth of up to VEIL_MAX_SUNS lights in
 * their light-space grids (propagate/sun_space.h: suns', and point and
 * spot lights' in the perspective form). Only over a dense EV,
 * so they share units with the sparse tables (9..13), never bound then. */
#define VEIL_MAX_SUNS 4
#define VEIL_TEX_SUN0 9
/* The surfaces of a frame under `veil fog` as a solid (scene/solid.h): the
 * r8 voxels (1: solid) and an r32f array of shadow maps, one layer a light. */
#define VEIL_TEX_SOLID 14
#define VEIL_TEX_SHADOW 15
#define VEIL_SOLID_MAP 256

/* A light as the GPU sees it: one shape for every shader (std140, 48 bytes).
 * Filled from scene/light.h's veil_light by veil_light_to_gpu(). */
VEIL_STRUCT_BEGIN(veil_gpu_light)
    VEIL_V4(position);  /* xyz: point, spot position (m); w: type, VEIL_LIGHT_* */
    VEIL_V4(direction); /* xyz: directional: unit travel direction; spot: its axis; w: spot cos(inner angle),
                           point: floor on r^2 (m^2, its radius squared) */
    VEIL_V4(color);     /* rgb: W/sr (point, spot) or W/m^2 (directional); w: spot cos(outer angle) */
VEIL_STRUCT_END(veil_gpu_light)

/* An exponential fog: density * exp(-falloff <x - origin, direction>) in its box. */
VEIL_STRUCT_BEGIN(veil_gpu_fog)
    VEIL_V4(direction); /* xyz: unit n; w: density at the origin plane */
    VEIL_V4(origin);    /* xyz: m; w: falloff (m^-1) */
    VEIL_V4(box_min);   /* xyz: m */
    VEIL_V4(box_max);   /* xyz: m */
VEIL_STRUCT_END(veil_gpu_fog)

/* The medium and the lights as every pass that reads them sees them — the
 * march (render/) and the volumetric stage (volumetric/) — with no camera
 * in it: one std140 uniform block at VEIL_UBO_MEDIUM, filled by
 * veil_lit_medium_fill() (propagate/lit_medium.h) and read through
 * propagate/shaders/lit_medium.glsl. */
VEIL_STRUCT_BEGIN(veil_medium_block)
    VEIL_V4(box_min);      /* xyz: the EV's medium, first voxel centre (m) */
    VEIL_V4(box_max);      /* xyz: last voxel centre (m) */
    VEIL_V4(tex_min);      /* xyz: texture coordinates are (x - tex_min) * tex_inv_size */
    VEIL_V4(tex_inv_size); /* xyz: m^-1 */
    VEIL_V4(sigma_t);      /* rgb: m^-1 per unit density */
    VEIL_V4(sigma_s);      /* rgb: m^-1 per unit density */
    VEIL_V4(shape);        /* x: floor on |S - X|^2 (m^2), y: voxel (m), z: HG g, w: 1 with emission */
    VEIL_IV4(counts);      /* x: lights, y: fogs, z: 1 with a volume (the EV), w: lights read from the OPVs
                              (on_opv; the other x - w from light-space grids: sun_step[k].w) */
    veil_gpu_light lights[VEIL_MAX_LIGHTS];
    veil_gpu_fog fogs[VEIL_MAX_FOGS];
    VEIL_IV4(sun_of[VEIL_MAX_LIGHTS / 4]); /* [l / 4][l % 4]: 1 + the light-space grid holding light l's
                                              optical depth; 0: its channel of the OPVs */
    VEIL_V4(sun_map[3 * VEIL_MAX_SUNS]);   /* 3k .. 3k+2: grid k's world -> texture rows (xyz . x + w) */
    VEIL_V4(sun_step[VEIL_MAX_SUNS]);      /* grid k: x: node spacing along the light (m), y: nodes along it,
                                              z: density samples of the last stretch (propagate/shaders/lit_medium.glsl),
                                              w: the light it holds */
    VEIL_V4(solid_origin); /* xyz: the frame's solid's min corner (m); w: its voxel (m), 0: no solid (scene/solid.h) */
    VEIL_IV4(solid_dims);  /* xyz: its voxels an axis; w: shadow maps (light l < w has layer l) */
    VEIL_V4(shadow[3 * VEIL_MAX_LIGHTS]);  /* light l: 3l, 3l+1: a sun's map coordinates dot(x, xyz) + w;
                                              3l+2: x: bias (m), y: bias per m along the light's path */
    VEIL_IV4(on_opv[VEIL_MAX_LIGHTS / 4]); /* [i / 4][i % 4], i < counts.w: the lights read from the OPVs, in order */
    /* A point or spot light's grid k (the perspective form of propagate/sun_space.h; sun_map[3k] then holds
       the texture's nodes along a, b, c and the planes' spacing in depth (voxels), sun_step[k].xy are 0): */
    VEIL_V4(sun_light[VEIL_MAX_SUNS]);     /* xyz: the light (m); w: 1 for a perspective grid, 0 for a sun's */
    VEIL_V4(sun_face[12 * VEIL_MAX_SUNS]); /* face f of grid k: [12k + 2f]: u0, v0, du, z0 (voxels);
                                              [12k + 2f + 1]: its first plane, columns along u and v, planes */
VEIL_STRUCT_END(veil_medium_block)

/* What the ray marcher (render/shaders/march.comp) reads besides the
 * medium block and its textures: the camera, the frame and the march's
 * own settings, one std140 uniform block at VEIL_UBO_MARCH. */
VEIL_STRUCT_BEGIN(veil_march_block)
    VEIL_V4(cam_pos);      /* xyz: camera position (m) */
    VEIL_V4(cam_fwd);      /* xyz: the image centre's direction (the view direction, moved by the lens shift) */
    VEIL_V4(cam_right);    /* xyz: right, scaled by tan(fov_x/2); w: the near clip distance along the view axis (m) */
    VEIL_V4(cam_up);       /* xyz: up, scaled by tan(fov_y/2); w: the far clip distance (m; FLT_MAX: none) */
    VEIL_V4(background);   /* rgb: radiance behind the medium */
    VEIL_V4(march);        /* x: step (m); the cache's gather (render/shaders/cache_gather.comp): y its rays a cell (0: off),
                              z its steps in the cache's cells, w the cache's cells a side of one of its cells
                              (a real >= 1: its grid in u.limits.yzw) */
    VEIL_V4(limits);       /* x: no step starts at or beyond this distance (m; 3e38: no limit); yzw: the gather's
                              cells along x, y, z (u.march.w of the cache's a side each) */
    VEIL_IV4(size);        /* x, y: image size (pixels); z: the first row of this dispatch's band */
    VEIL_UV4(flags);       /* x: -, y: skip empty bricks, z: jitter seed, w: per-pixel end */
    VEIL_V4(octave);       /* volumetric multiple scattering: x: a, y: b, z: c, w: octaves (0: off) */
    VEIL_V4(diffusion);    /* xyz: the volumetric field's texture origin (m); w: its veil_field_kind */
    VEIL_V4(diffusion_inv); /* xyz: texture coordinates per m; w: the light cache's nz (its grid's cells along z) */
VEIL_STRUCT_END(veil_march_block)

/* ---- the sparse extinction volume (volume/sparse.h) --------------------- */

/* A sparse EV keeps only the VEIL_BRICK^3 bricks whose interpolation cell
 * holds density, each in an atlas with its 8 voxels and the next brick's
 * first (VEIL_SPARSE_APRON texels a side, so hardware trilinear filtering
 * never leaves the brick), found through two tables: a top table of nodes
 * (VEIL_SPARSE_NODE^3 bricks, 128^3 voxels) and, per node, a table of slots. */
#define VEIL_SPARSE_APRON 9
#define VEIL_SPARSE_NODE 16
#define VEIL_SPARSE_NODE_BRICKS (VEIL_SPARSE_NODE * VEIL_SPARSE_NODE * VEIL_SPARSE_NODE)
/* The escape field of a sparse volume: a 3^3 lattice per brick (every 4
 * voxels, its first and last texel on the brick's faces). */
#define VEIL_SPARSE_ESCAPE 3
/* Midpoint steps (voxels) of the optical depth marched through a sparse volume. */
#define VEIL_SPARSE_OD_STEP 0.5
#define VEIL_SPARSE_GROUP 4 /* 4^3 atlas texels per work group */
#define VEIL_UBO_SPARSE 3
#define VEIL_TEX_SPARSE_TOP 9     /* texture unit: r32ui buffer, the top table (0: empty node, else node + 1) */
#define VEIL_TEX_SPARSE_NODES 10  /* texture unit: r32ui buffer, the nodes' tables (0: empty brick, else slot + 1) */
#define VEIL_TEX_SPARSE_COORDS 11 /* texture unit: rgba32i buffer, each slot's brick */
#define VEIL_TEX_SPARSE_ESCAPE 12 /* texture unit: r32f 3D, the escape field per brick */
#define VEIL_TEX_SPARSE_LIST 13   /* texture unit: r32i buffer, slots in the order a pass takes them */
#define VEIL_IMAGE_SPARSE_OUT 0   /* image unit: what a sparse pass writes (atlas-shaped) */

VEIL_STRUCT_BEGIN(veil_sparse_block)
    VEIL_IV4(bricks);    /* xyz: bricks of the grid; w: slots in use */
    VEIL_IV4(top);       /* xyz: nodes of the top table; w: - */
    VEIL_IV4(atlas);     /* xyz: the atlas in bricks; w: - */
    VEIL_V4(origin);     /* xyz: the grid's min corner (m); w: voxel edge (m) */
    VEIL_V4(inv_atlas);  /* xyz: 1 / atlas texels per axis; w: - */
    VEIL_V4(dims);       /* xyz: the grid's voxels per axis (float); w: - */
VEIL_STRUCT_END(veil_sparse_block)

/* ---- passes over the extinction volume's voxels (volume/) -------------- */

/* The RBF splat (volume/shaders/inject_rbf.comp) and the occupancy bricks
 * (volume/shaders/occupancy.comp) read the grid from this block. */
#define VEIL_UBO_GRID 5
VEIL_STRUCT_BEGIN(veil_grid_block)
    VEIL_IV4(dims);   /* xyz: the EV's voxels; w: the splat: this dispatch's first brick (x fastest) */
    VEIL_IV4(bricks); /* xyz: VEIL_BRICK^3 bricks per axis; w: - */
    VEIL_V4(origin);  /* xyz: the grid's min corner (m); w: voxel edge (m) */
VEIL_STRUCT_END(veil_grid_block)
#ifndef VEIL_GLSL
_Static_assert(sizeof(veil_grid_block) == 48, "veil_grid_block: std140, three 16-byte members");
#endif

/* ---- screen-space multiple scattering (render/spread.h) ---------------- */

#define VEIL_SPREAD_GROUP 8     /* 8x8 pixels per work group, every spread pass */
#define VEIL_SPREAD_MAX_LEVEL 12 /* K <= 12: a texel of level 12 spans 4096 pixels */
/* Image units of the spread passes (their programs bind nothing else). */
#define VEIL_SPREAD_IN_L 0      /* rgba32f: input radiance L behind the medium */
#define VEIL_SPREAD_IN_T 1      /* rgba32f: T rgb, P (the march's aov_t) */
#define VEIL_SPREAD_IN_S 2      /* rgba32f: single rgb, depth (the march's aov_s) */
#define VEIL_SPREAD_IN_Q 3      /* rgba32f: out-scattered single rgb, its P (the march's aov_q) */
#define VEIL_SPREAD_OUT_SC 4    /* rgba32f: chain L_sc rgb, W (pixels) */
#define VEIL_SPREAD_OUT_P 5     /* rgba32f: chain P, P * s (s: pixels per metre), -, - */
#define VEIL_SPREAD_OUT_SSC 6   /* rgba32f: chain L_ssc rgb, P_ssc */
#define VEIL_SPREAD_OUT 7       /* rgba32f: the spread light rgb, a: the level read */
/* Texture units of the spread passes: the chains, sampled. */
#define VEIL_SPREAD_TEX_SC 0
#define VEIL_SPREAD_TEX_P 1
#define VEIL_SPREAD_TEX_SSC 2
#define VEIL_UBO_SPREAD 1
/* Interpolation of the chains (paper's Table 1). */
#define VEIL_INTERP_LINEAR_BILINEAR 0 /* linear between levels, bilinear in a level */
#define VEIL_INTERP_LINEAR_BICUBIC 1  /* linear between levels, cubic B-spline in a level (4 bilinear taps) */
#define VEIL_INTERP_CUBIC_BICUBIC 2   /* cubic B-spline between levels too */

VEIL_STRUCT_BEGIN(veil_spread_block)
    VEIL_V4(sigma_a);    /* rgb: C_a, m^-1 per unit density; w: their mean */
    VEIL_V4(sigma_s);    /* rgb: C_s, m^-1 per unit density; w: their mean */
    VEIL_V4(params);     /* x: c (pixels), y: mask epsilon, z: HG g, w: radians per pixel at the centre */
    VEIL_V4(sep);        /* x: T_y, y: eps_y (radiance), z: T_d', w: eps_d' (density m) */
    VEIL_V4(weights_lo); /* filter taps 0..3 */
    VEIL_V4(weights_hi); /* x, y: filter taps 4, 5; z: the separated chain's level; w: - */
    VEIL_IV4(size);      /* x, y: the image; z, w: level 0 of the chains (padded to a multiple of 2^K) */
    VEIL_IV4(mode);      /* x: filter taps (2, 4, 6); y: veil_spread_interp; z: K; w: the level being built */
    VEIL_UV4(flags);     /* x: mask, y: luminance weighting, z: density blur, w: separation */
VEIL_STRUCT_END(veil_spread_block)

/* Premoze et al. (2004), Iser & Elek (2018) Eq. 1-3: the standard deviation
 * (m) of the Gaussian spread of a pencil of light over a path whose
 * density integral is s (density m; the "density-scaled distance" with the
 * reference medium of unit density), with scattering sa, ss (m^-1 per unit
 * density) and HG asymmetry g:
 *   W^2 = 1 / (2 (2 sa / (3 s) + 4 / (s^3 ss (1 - g))))
 *       = k s / (8 / s^2 + (4/3) sa k),   k = ss (1 - g).
 * The second form has no division by zero and no 0/0: s -> 0 gives 0
 * (8/s^2 -> inf), ss -> 0 or g -> 1 gives k = 0 and 0, sa -> 0 gives
 * s^(3/2) sqrt(k/8); large s saturates at sqrt(3 s / (4 sa)) (inf only where
 * s or k s is). Inputs must not be NaN; g is clamped to [-1, 1]. */
VEIL_FN float veil_spread_width(float s, float sa, float ss, float g)
{
    float k = ss * (1.0 - VEIL_MINF(VEIL_MAXF(g, -1.0), 1.0));
    float s2 = s * s; /* s^2 = 0 (underflow, s < 1e-19) would divide by zero: W is 0 there */
    if (!(s2 > 0.0) || !(k > 0.0)) return 0.0;
    return VEIL_SQRTF(k * s / (8.0 / s2 + VEIL_FLOAT(4.0 / 3.0) * sa * k));
}

/* The MIP level whose blur matches a spread of w pixels (Elek et al.
 * 2013): k = clamp(log2(w / c), 0, K). w <= c (and w = 0) is level 0; inf
 * is K. */
VEIL_FN float veil_spread_level(float w, float c, float K)
{
    if (!(w > c)) return 0.0;
    return VEIL_MINF(VEIL_LOG2F(w / c), K);
}

/* Relative luminance of linear RGB (Rec. 709 primaries). */
#define VEIL_LUM_R 0.2126
#define VEIL_LUM_G 0.7152
#define VEIL_LUM_B 0.0722

/* ---- the diffusion estimate (volumetric/volumetric.h) ------------------------ */

#define VEIL_DIFFUSION_GROUP 4  /* 4^3 cells per work group */
#define VEIL_IMAGE_DIFF_SRC 0   /* image unit: rgba32f source S (rgb), density (a) */
#define VEIL_IMAGE_DIFF_PHI 1   /* image unit: rgba32f fluence phi (rgb) */
#define VEIL_UBO_DIFFUSION 2
#define VEIL_DIFFUSION_MAX_EXTENT 1e4 /* m: a fog box larger than this gets no grid; escape paths end here */
/* What a volumetric field holds (veil_march_block.diffusion.w, as a float):
 * the fluence of the diffusion solve, or the octaves' gate, the chance that
 * light scattered at a point scatters again (volumetric/volumetric.h). */
#ifdef VEIL_GLSL
#define VEIL_FIELD_NONE 0
#define VEIL_FIELD_FLUENCE 1
#define VEIL_FIELD_ESCAPE 2
#define VEIL_FIELD_CACHE 3
#else
typedef enum veil_field_kind {
    VEIL_FIELD_NONE = 0,
    VEIL_FIELD_FLUENCE = 1,
    VEIL_FIELD_ESCAPE = 2,
    VEIL_FIELD_CACHE = 3 /* the light cache: fluence rgb of light scattered at least once, and its flux */
} veil_field_kind;
#endif

VEIL_STRUCT_BEGIN(veil_diffusion_block)
    VEIL_V4(origin);     /* xyz: the first cell's centre (m); w: cell edge h (m) */
    VEIL_V4(sigma_a);    /* rgb: m^-1 per unit density */
    VEIL_V4(sigma_tr);   /* rgb: transport sigma_a + sigma_s (1 - g), m^-1 per unit density; w: vacuum below this sigma_tr rho h */
    VEIL_IV4(dims);      /* xyz: cells; w: the parity updated (red-black) */
    VEIL_V4(relax);      /* x: over-relaxation omega */
VEIL_STRUCT_END(veil_diffusion_block)

/* ---- the light cache (volumetric/cache.h) ------------------------------ */

/* Photons traced from the lights through the medium by delta tracking
 * against a per-cell majorant; after their first scattering (from their
 * start for the medium's own emission) every piece of path in a cell adds
 * w len / V to the cell's fluence (the track-length estimator) and
 * lum(w) len omega / V to its flux, summed over a photon's visit to the cell
 * and added once when it leaves. Sums are signed 64-bit fixed point (two
 * uint words, low first) added with integer atomics: order-free, so a seed
 * gives the same cache bit for bit. */
#define VEIL_CACHE_GROUP 64        /* photons per work group */
#define VEIL_CACHE_CELL_GROUP 4    /* 4^3 cells per work group (bounds, resolve) */
#define VEIL_CACHE_SUMS 13         /* per cell: fluence r, g, b and flux x, y, z of the light scattered once
                                      (emission: not yet scattered); the odd photons' luminance fluence (all);
                                      fluence rgb and flux xyz of the light scattered more often */
#define VEIL_CACHE_LATER 14        /* the word where the second set of sums begins */
#define VEIL_CACHE_WORDS (2 * VEIL_CACHE_SUMS)
/* A piece of path (at most a cell's diagonal) scores at most
 * 2^VEIL_CACHE_FIXED_BITS units (volumetric/cache.c derives the unit from
 * the largest score a photon can make); a visit is added before it holds
 * more than VEIL_CACHE_VISIT_DIAGONALS diagonals of path, so one add is at
 * most 2^30 units and fits an int32, and 2^33 adds fit a cell's 64 bits. */
#define VEIL_CACHE_FIXED_BITS 20
#define VEIL_CACHE_VISIT_DIAGONALS 1024
/* SSBO bindings of the cache's own passes (GL guarantees 8: 0..7) */
#define VEIL_BIND_CACHE_SUM 0      /* uint[cells * VEIL_CACHE_WORDS] */
#define VEIL_BIND_CACHE_CELL 1     /* vec2[cells]: majorant density, emission weight */
#define VEIL_BIND_CACHE_EMIT 2     /* the emitting cells: uvec4 (cell, the CDF up to it and p as float bits, -);
                                      for the environment, its table (veil_env_table: two uvec4 of float bits) */
#define VEIL_BIND_CACHE_COUNT 3    /* uint[4]: photons cut at the step cap, scores clamped, majorant misses, -;
                                      then the energy account's int64 sums (below) */
#define VEIL_BIND_CACHE_FREE 4     /* float[cells]: the part of each cell not inside a frame's solid (scene/solid.h),
                                      kept as the flux's alpha: the march divides by it, interpolated */
/* The energy account of the light that scattered (or was emitted): per
 * group of photons (photon n in group n mod VEIL_CACHE_ENERGY_GROUPS, for a
 * standard error), per channel, the weight that entered (at its first
 * scattering; emission at its start), left the grid, was absorbed, and the
 * collision estimator sum over tentative collisions of w sigma_t / sigma_bar
 * (whose mean is the integral of sigma_t phi) and the track length sum of
 * w len (whose mean is the integral of phi: the cells' fluence times their
 * volume). Units: power.w per W (a photon's channel weight is at most 2^20
 * units); the collision sum 2^-16 of that, as a photon makes at most 2^16
 * tentative collisions; the track length 2^-16 / (sqrt(3) h) of it per W m. */
#define VEIL_CACHE_ENERGY_GROUPS 8
#define VEIL_CACHE_ENERGY_IN 0
#define VEIL_CACHE_ENERGY_OUT 1
#define VEIL_CACHE_ENERGY_ABSORBED 2
#define VEIL_CACHE_ENERGY_COLLISIONS 3
#define VEIL_CACHE_ENERGY_TRACK 4
#define VEIL_CACHE_ENERGY_LATER_IN 5    /* the weight that scattered again (emission: at all): the later light */
#define VEIL_CACHE_ENERGY_LATER_TRACK 6 /* the later light's track length (units as _TRACK) */
#define VEIL_CACHE_ENERGY_KINDS 7
#define VEIL_CACHE_ENERGY_WORDS (2 * 3 * VEIL_CACHE_ENERGY_KINDS * VEIL_CACHE_ENERGY_GROUPS)
#define VEIL_UBO_CACHE 7
/* The cache is one rgba32f texture of stacked grids (cells nx, ny, VEIL_CACHE_SLABS nz): z in [0, nz) the
 * fluence rgb with the odd photons' luminance fluence in a, z in [nz, 2 nz) the luminance-weighted flux xyz
 * with the cell's part outside a frame's solid in a, then the same two of the later light alone (scattered
 * more than once; emission: scattered), in [2 nz, 3 nz) (a: the cell's majorant density) and [3 nz, 4 nz),
 * and the gathered light in [4 nz, 5 nz) (below). One sampler reads them all (the march clamps z within a
 * slab, so filtering never crosses): on Mesa 22's
 * llvmpipe a second 3D sampler read with texture() in the march returned 0 on all but the first
 * invocation of each row of a work group (texelFetch did not). */
#define VEIL_IMAGE_CACHE 0         /* image unit: the cache, written by the resolve pass (and its slab 4 by the gather) */
/* The slabs of the cache's texture: the four above, and a fifth the camera's (render/shaders/cache_gather.comp):
 * the later light scattered towards the camera, gathered along rays through the medium from the cells' lobes,
 * rewritten for each camera; the volumetric stage leaves it 0. */
#define VEIL_CACHE_SLABS 5
#define VEIL_GATHER_GROUP 4        /* 4^3 cells a work group of the gather */
#define VEIL_GATHER_MAX_OPT 0.5    /* the gather's steps split above this optical thickness (reduced extinction) */
#define VEIL_GATHER_MAX_LOBE 0.9   /* the gather's second technique: the light's lobe at most this peaked */
#define VEIL_GATHER_MAX_CELLS 64   /* the gather's cells along the grid's longest side, at most, where the march
                                      is not told (render/march.h gather_cells; coarser: cubes of s cache cells) */
/* The photons' work (steps: a piece of path in a cell, or a tentative
 * collision). volumetric/cache.c estimates the steps a photon takes from
 * the cells' majorants; the photons of a cache take at most
 * VEIL_CACHE_STEPS_PER_PHOTON times the budget's photons in all (fewer
 * photons where the medium is thick, never under VEIL_CACHE_MIN_PHOTONS;
 * thicker than that, no cache), and each photon is cut at 8 times the
 * estimate, within [VEIL_CACHE_MIN_CUT, VEIL_CACHE_MAX_CUT] (counted). */
#define VEIL_CACHE_STEPS_PER_PHOTON 512
#define VEIL_CACHE_MIN_PHOTONS 4096
#define VEIL_CACHE_MIN_CUT 4096
#define VEIL_CACHE_MAX_CUT 65536
/* Source kinds of a dispatch (veil_cache_block.source.x). */
#define VEIL_CACHE_SUN 0
#define VEIL_CACHE_CONE 1          /* point and spot lights: directions in a cone */
#define VEIL_CACHE_EMISSION 2      /* the medium's emission, by cell */
#define VEIL_CACHE_ENV 3           /* the environment's rest (scene/environment.h), by texel block */

VEIL_STRUCT_BEGIN(veil_cache_block)
    VEIL_V4(origin);   /* xyz: the grid's min corner (m); w: cell edge h (m) */
    VEIL_IV4(dims);    /* xyz: cells; w: emitting cells (VEIL_CACHE_EMISSION) */
    VEIL_V4(sigma_a);  /* rgb: m^-1 per unit density; w: the majorant's floor (m^-1) where a cell has density */
    VEIL_V4(sigma_s);  /* rgb: m^-1 per unit density; w: HG g */
    VEIL_V4(scale);    /* x: units per score (W/m^2)^-1, y: W/m^2 per unit, z: 1 / V (m^-3), w: max sigma_t per density */
    VEIL_UV4(source);  /* x: VEIL_CACHE_*, y: the light, z: the first photon of this dispatch, w: photons of the source */
    VEIL_UV4(seed);    /* x: the seed, y: the source's index among the cache's, z: a photon's step cap, w: 1: a
                          photon ends at its first scattering (the medium is too thick for more) */
    VEIL_V4(power);    /* rgb: W per photon (sun, cone: before a spot's falloff; emission: W per photon per
                          (W m^-3 sr^-1 of emission, 1 / p of the cell)), w: the energy account's units per W */
    VEIL_V4(src0);     /* sun: a corner of the rectangle photons start on; cone: the apex (m); environment:
                          the centre of the grid's bounding sphere (m), w: its radius (m) */
    VEIL_V4(src1);     /* sun: the rectangle's first edge (m); cone: the axis (unit), w: cos of the half-angle;
                          environment: the map frame's x axis in the world, w: the map's width (texels) */
    VEIL_V4(src2);     /* sun: the second edge (m); environment: the frame's y axis, w: the map's height */
    VEIL_V4(src3);     /* sun: the travel direction (unit); environment: the frame's z axis, w: the table's
                          block (texels a side) */
VEIL_STRUCT_END(veil_cache_block)

/* The fixed point: a score s >= 0 (or a signed flux component) is added as
 * the integer floor(s * units + xi), xi uniform in [0, 1): unbiased
 * (E = s * units exactly, for any s), off by less than one unit, and
 * clamped to +-(2^31 - 128), the largest float below 2^31 (a score over 2^VEIL_CACHE_FIXED_BITS units is
 * outside the bound the unit was derived from: counted, never wrapped). */
VEIL_FN int veil_cache_fixed(float s_units, float xi)
{
    float v = VEIL_FLOORF(s_units + xi);
    v = VEIL_MINF(VEIL_MAXF(v, -2147483520.0), 2147483520.0);
    return VEIL_INT(v);
}

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

/* exp(-x), a step's transmittance for its optical thickness x >= 0, held at
 * most 1. IEEE exp gives exp(-x) <= 1 for x >= 0, but a GPU's exp is an
 * approximate exp2 of x log2(e) and rounds exp(-tiny) to 1 + 1 ulp (an NVIDIA
 * H200: every empty pixel's T = 1 + 2^-23, issue 42); a ray's product of
 * such steps would climb further. The bound costs a min a channel. */
VEIL_FN float veil_step_transmittance(float x) { return VEIL_MINF(VEIL_EXPF(-x), 1.0); }

/* A pixel's alpha from its transmittance per channel: 1 - mean(T), held in
 * [0, 1]. With every T in [0, 1] the IEEE mean is in [0, 1] too, but a GPU
 * may divide by 3 as a product with a rounded 1/3; a compositor that
 * unpremultiplies by a negative alpha flips the colour's sign. */
VEIL_FN float veil_alpha(float tr, float tg, float tb)
{
    return VEIL_MINF(VEIL_MAXF(1.0 - (tr + tg + tb) / 3.0, 0.0), 1.0);
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
