// Internals of drift micro shared by its files and the unit tests: the point hierarchy
// (hierarchy.c), its lighting (lighting.c), the BRDF warp (warp.c) and one gather into a
// micro-buffer (microbuffer.c).
#ifndef DRIFT_MICRO_INTERNAL_H
#define DRIFT_MICRO_INTERNAL_H

#include "drift/micro.h"

// --- HIERARCHY (thesis §6.2.1) ---

// A complete binary tree over leaf_count = 2^k scene points, stored as arrays: node i has the
// children 2i + 1 and 2i + 2; the leaves are the last leaf_count nodes, leaf j = node
// leaf_count - 1 + j standing for scene point point_of[j]. Each node is a bounding sphere
// (center, radius), a cone of normals (axis, cos of its half angle; -1: every direction) and
// the radiance it reflects. A leaf's is that of its disc's two sides (front: the side its
// axis points to); every node's is also kept as an "ambient cube" (six directions +x, -x,
// +y, -y, +z, -z, each side of each leaf weighted by the square of its normal's component
// along them) so that a node is seen with the radiance of the leaves that face the viewer:
// a single mean would show a box's lit top to a point below it (docs/micro.md).
typedef struct drift__micro_tree {
    uint32_t leaf_count, node_count;
    uint32_t *point_of; // leaf_count: the drift_points index of each leaf
    drift_vec3 *center;
    float *radius;
    drift_vec3 *axis;
    float *cone_cos;
    drift_vec3 *albedo; // area-weighted mean diffuse reflectance kd
    drift_vec3 *front;  // outgoing radiance of the front side (set at the leaves)
    drift_vec3 *back;   // of the back side
    drift_vec3 *cube;   // 6 a node: the radiance-weighted sums along +x, -x, +y, -y, +z, -z
    float *cube_weight; // 6 a node: the weights' sums
    float leaf_radius;  // r = sqrt(A / (pi n)): the disc one point stands for
    uint8_t *covered;   // per node: bit 0 (leaves) the front side, bit 1 the back lies under
                        // another surface (a floor laid over a floor), left out of the pull;
                        // bit 2 every side of the node's leaves does (the gathers cull it)
} drift__micro_tree;

// Orders the points by a median-split BSP along the largest extent (O(n log n)) and allocates
// the nodes; leaf_count must be points->count, a power of two. Then drift__micro_tree_refit.
drift_result drift__micro_tree_create(drift_context *ctx, const drift_points *points,
                                      drift__micro_tree *tree);
void drift__micro_tree_destroy(drift_context *ctx, drift__micro_tree *tree);
// Leaves from the points' current positions and normals (radius from their current area),
// then every interior sphere and cone from its children's, bottom-up.
void drift__micro_tree_refit(drift__micro_tree *tree, const drift_points *points);
// Marks the leaf sides that another surface covers within half a leaf radius along their
// normal (drift__micro_tree.covered): such a side is seen by nothing, and a node mixing it
// with the cover would show the cover's light diluted by its darkness (on cornell-glossy the
// glossy floor 0.5 mm above the box's own halved the floor's radiance).
void drift__micro_tree_cover(drift_context *ctx, drift__micro_tree *tree, const drift_accel *accel);
// Interior albedo and radiance from the leaves' (equal areas: a complete tree over equal-area
// points): albedo, front and back the children's means (a child's side that faces its
// parent's front counts toward the front), the ambient cubes their sums.
void drift__micro_tree_pull(drift__micro_tree *tree);
// The radiance node i sends toward `toward` (any length; from the node to the viewer).
drift_vec3 drift__micro_tree_radiance(const drift__micro_tree *tree, uint32_t i, drift_vec3 toward);
// Whether node i shows any leaf side toward `toward` (from the node to the viewer): false
// when all that faces that way is covered. A node never pulled (no weights) counts as seen.
bool drift__micro_tree_seen(const drift__micro_tree *tree, uint32_t i, drift_vec3 toward);
// The leaf nearest to x (branch and bound over the spheres).
uint32_t drift__micro_tree_nearest_leaf(const drift__micro_tree *tree, drift_vec3 x);
// The same among the leaves a gather point p (normal n) can see at a ray's hit x of geometric
// normal ng: in front of p's tangent plane and on a surface turned like the hit's (|axis . ng|
// >= 0.5). p NULL: every leaf. Falls back to the last leaf when none qualifies: check.
uint32_t drift__micro_tree_nearest_leaf_seen(const drift__micro_tree *tree, drift_vec3 x,
                                             const drift_vec3 *p, drift_vec3 n, drift_vec3 ng);

// --- LIGHTING (§6.4, one bounce) ---

// Direct light reflected by the leaves' diffuse lobe (kd / pi E) on both sides, `samples` light
// samples a side, ray-traced visibility; and the leaves' albedo. Returns the shadow rays cast.
uint64_t drift__micro_light_leaves(drift_context *ctx, const drift_scene *scene,
                                   const drift_accel *accel, const drift_points *points,
                                   drift__micro_tree *tree, int32_t samples, uint32_t seed);

// --- LIGHTING MODES (§6.4: lighting.c, radiosity.c, photons.c) ---

#define DRIFT_MICRO_MAX_BOUNCES      8
#define DRIFT_MICRO_MAX_PHOTON_K     256
#define DRIFT_MICRO_RADIOSITY_LEAVES 32 // leaves an element holds at most (up to 2^14 points)

// The defaults and the checks of the lighting fields of drift_micro_params.
void drift__micro_lighting_resolve(drift_micro_params *p);
bool drift__micro_lighting_valid(const drift_micro_params *p);

// Lights the leaves (direct light, then the bounces of params->lighting) and pulls the tree;
// adds to stats->rays, sets stats->direct_ms, bounces_ms and photons.
drift_result drift__micro_light_points(drift_context *ctx, const drift_scene *scene,
                                       const drift_accel *accel, const drift_points *points,
                                       drift__micro_tree *tree, const drift_micro_params *params,
                                       drift_micro_stats *stats);

// Radiosity (Jacobi) over the hierarchy. The tree is cut into elements: the largest nodes
// with at most element_leaves leaves whose normal cone is within 30 degrees (a leaf always
// is one). Each iteration pulls the last increment of radiance up the tree and gathers it at
// every element, on both sides of its cone's axis, with a diffuse micro-buffer of K =
// buffer_size (the frame unrotated); each leaf of the element gets kd times the side it faces
// as the next increment. Increments are non-negative, so the total only grows; with albedo
// below 1 they shrink geometrically.
typedef struct drift__micro_radiosity_desc {
    const drift_accel *accel; // the post-traversal ray casting (NULL: none)
    int32_t iterations;       // bounces added beyond the leaves' current radiance
    int32_t buffer_size;
    uint32_t element_leaves;
} drift__micro_radiosity_desc;

// On entry the leaves hold their first bounce (front and back); on return that plus the
// `iterations` increments, not pulled. out_increments (may be NULL; iterations + 1 entries)
// gets the mean over leaves of the luminance of front + back of each: [0] the entry's.
drift_result drift__micro_radiosity(drift_context *ctx, drift__micro_tree *tree,
                                    const drift_points *points,
                                    const drift__micro_radiosity_desc *desc, double *out_increments,
                                    uint64_t *out_rays);

// A photon map (Jensen 1996, the thesis's Fig. 6.9): light paths traced from the lights with
// drift's accel, scattered by the BSDF (mirror and glossy lobes included: caustics), stored
// where they land on a surface with a diffuse lobe after min_scatter..max_scatter scatterings.
typedef struct drift__micro_photon {
    drift_vec3 position;
    drift_vec3 normal; // the geometric normal on the side the photon arrived from
    drift_vec3 power;  // flux (W) arriving
} drift__micro_photon;

typedef struct drift__micro_photon_desc {
    uint32_t paths;
    int32_t min_scatter, max_scatter; // 0: the light's own first hits
    uint32_t seed;
} drift__micro_photon_desc;

typedef struct drift__micro_photon_map {
    drift__micro_photon *photons; // in kd-tree order: the median of a range splits it
    uint8_t *axis;                // split axis of each range's median
    uint32_t count;
    drift_vec3 emitted; // the flux that left the lights, summed over the paths
    uint64_t rays;
} drift__micro_photon_map;

drift_result drift__micro_photons_trace(drift_context *ctx, const drift_scene *scene,
                                        const drift_accel *accel,
                                        const drift__micro_photon_desc *desc,
                                        drift__micro_photon_map *out_map);
void drift__micro_photons_destroy(drift_context *ctx, drift__micro_photon_map *map);
// Irradiance at x on the side of the unit normal n: the k nearest photons that arrived on
// a surface facing n (normals within 60 degrees), their flux over pi r^2, r the k-th's distance;
// at most max_radius away (INFINITY: no bound), fewer than k within it over pi max_radius^2.
drift_vec3 drift__micro_photons_irradiance(const drift__micro_photon_map *map, drift_vec3 x,
                                           drift_vec3 n, int32_t k, float max_radius);
// Adds kd / pi E of both sides to every leaf's front and back (not pulled).
void drift__micro_photons_light_leaves(drift_context *ctx, const drift__micro_photon_map *map,
                                       const drift_points *points, drift__micro_tree *tree,
                                       int32_t k);

// --- WARP (§6.2.3) ---

// A BRDF slice tabulated over the unit disc of projected directions (omega_x, omega_y),
// parametrised by (u, t) in [-1, 1]^2 with omega_x = u, omega_y = t sqrt(1 - u^2) so that the
// table has no cells outside the disc; density f_r(omega) sqrt(1 - u^2) (f_r cos d omega =
// f_r d omega_x d omega_y). The marginal CDF runs over u, the conditional ones over t.
// A sharp lobe would cover a few cells of the disc: its table may instead cover only a cap
// of directions around the lobe's axis (cap.z, local), the disc scaled by `scale` = sin of
// the cap's half angle (omega_x = scale u, ... in the cap's frame), density f_r cos dω over
// (u, t).
#define DRIFT_MICRO_MAX_WARP 128

typedef struct drift__micro_warp {
    int32_t n;                                // table cells a side
    float marginal[DRIFT_MICRO_MAX_WARP + 1]; // over the n columns of u, unnormalised
    float conditional[DRIFT_MICRO_MAX_WARP * (DRIFT_MICRO_MAX_WARP + 1)]; // per column, over t
    float rho;       // integral of the slice: its directional albedo
    float scale;     // 1: the whole hemisphere; < 1: the cap of half angle asin(scale)
    drift_frame cap; // the cap's frame in local coordinates (identity for the hemisphere)
} drift__micro_warp;

// Tabulates the slice `lobe(omega, user)` (omega unit, local, z >= 0; f_r without the
// cosine) and its CDFs over the hemisphere.
typedef float (*drift__micro_lobe_fn)(drift_vec3 omega, const void *user);
void drift__micro_warp_build(drift__micro_warp *warp, int32_t n, drift__micro_lobe_fn lobe,
                             const void *user);
// The same over the cap of directions within asin(scale) of `axis` (unit, local, z > 0):
// for a lobe with (almost) all of f_r cos there. scale >= 1 is the hemisphere.
void drift__micro_warp_build_cap(drift__micro_warp *warp, int32_t n, drift_vec3 axis, float scale,
                                 drift__micro_lobe_fn lobe, const void *user);
// The half angle's sine of the cap around a Phong lobe of exponent `exponent` that holds all
// but 10^-3 of its integral (cos^(n+1) of the angle), or 1 (the hemisphere) past 70 degrees.
float drift__micro_phong_cap(float exponent);
// The cosine lobe 1/pi (the Nusselt map).
void drift__micro_warp_build_diffuse(drift__micro_warp *warp, int32_t n);
// Phi: a point of [0, 1]^2 -> a unit local direction; *out_pdf gets p_omega = f_r cos / rho
// there (solid angle measure).
drift_vec3 drift__micro_warp_forward(const drift__micro_warp *warp, drift_vec2 xy, float *out_pdf);
// Phi^-1: a unit local direction with z >= 0 -> its point of [0, 1]^2.
drift_vec2 drift__micro_warp_inverse(const drift__micro_warp *warp, drift_vec3 omega);

// --- MICRO-BUFFER (§6.2.2) ---

#define DRIFT_MICRO_MAX_K      32
#define DRIFT_MICRO_BOUND_BINS 128

// A K x K micro-buffer's pixels through one warp: direction (local) and solid angle of each.
typedef struct drift__micro_pixels {
    int32_t k;
    drift_vec3 dir[DRIFT_MICRO_MAX_K * DRIFT_MICRO_MAX_K];
    float omega[DRIFT_MICRO_MAX_K * DRIFT_MICRO_MAX_K];
    float omega_max; // the largest of omega: a node bigger than it is refined in any pixel
    // By the cosine z of a direction to the warp's axis (bin floor(z^2 BINS)): at least the
    // omega of any pixel the warp's inverse can put a direction of that bin in, so that a
    // node bigger than it is refined without the inverse (the same cut, bit for bit).
    float omega_bound[DRIFT_MICRO_BOUND_BINS];
} drift__micro_pixels;

void drift__micro_pixels_make(drift__micro_pixels *pixels, const drift__micro_warp *warp,
                              int32_t k);

// What one gather reads.
typedef struct drift__micro_gather_desc {
    const drift__micro_tree *tree;
    const drift_accel *accel; // NULL: no ray casting
    const drift__micro_warp *warp;
    const drift__micro_pixels *pixels;
    float cut_scale;
    // Non-NULL: the glossy lobes of the surfaces the rays hit reflect the direct light toward
    // p on the fly (one light sample a pixel, sampler key `seed`), the thesis's on-the-fly
    // radiance for non-diffuse nodes; the nodes carry only the diffuse lobe's.
    const drift_scene *scene;
    uint32_t seed;
} drift__micro_gather_desc;

// What one gather did.
typedef struct drift__micro_gather_stats {
    uint64_t gathers, visited, splats, post_leaves, rays, empty, cast;
} drift__micro_gather_stats;

// The micro-buffer of the gather point p with local frame `frame` (z: the normal the
// hemisphere is over) and geometric normal ng (for ray origins): node of each pixel (-1:
// none; out_node may be NULL) and the mean radiance over the K^2 pixels (empty ones are 0).
// Optional checks for the tests: when `splat_ok` is given it is cleared if a splatted node
// was bigger than cut_scale x its pixel's solid angle, or a post-list leaf was not.
drift_vec3 drift__micro_gather(const drift__micro_gather_desc *desc, drift_vec3 p,
                               const drift_frame *frame, drift_vec3 ng, int32_t *out_node,
                               drift__micro_gather_stats *stats, bool *splat_ok);

#endif // DRIFT_MICRO_INTERNAL_H
