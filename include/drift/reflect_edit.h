// drift reflect_edit: interactive reflection editing (Ritschel, Okabe, Thormählen & Seidel
// 2009; thesis ch. 7). Point constraints re-aim the reflection rays of a scene; a
// moving-least-squares rotation field carries them smoothly over the surface and passes
// exactly through each constraint. docs/reflection-editing.md has the equations.
//
// A constraint n: the red handle p_n on the mirror, the green handle g_n on the reflected
// object, and its generating view (the eye it was made from). From them, at commit:
//   r_n = the physical reflection at p_n of the ray from the eye      (eq. 7.1)
//   e_n = normalize(g_n - p_n)
// For a surface point q (eqs. 7.2-7.7):
//   w_n(q) = 1 / d(p_n, q)^2                                          (7.3)
//   R(q)   = ortho(sum_n w_n e_n r_n^T)                                (7.5)
//   R_a(q) = ortho(a(q) R(q) + (1 - a(q)) r r^T)                       (7.7)
//   e(q)   = R_a(q) r(q)                                               (7.6)
// r(q) is the current view's reflection, so edits stay view-dependent; R(q) depends on the
// surface point and the constraints only (never on the view): drift_reflection_edits_rotation
// takes no camera, and a renderer may keep R per surface point while the edits stand.
//
// STEP BY STEP
//   drift_reflection_edits *edits = NULL;
//   drift_reflection_edits_load(ctx, scene, accel, "room.edit.json", &edits);  // or _create +
//   drift_reflection_edits_add_constraint(edits, &(drift_reflection_constraint){ ... });
//   drift_reflection_edits_commit(edits);           // derives r_n, e_n and geodesic distances
//   drift_edit_point q = drift_edit_point_from_surface(&surface);
//   drift_vec3 e = drift_reflection_edits_direction(edits, &q, r);   // e(q) for r(q)
//   drift_reflection_edits_destroy(edits);
//
// Threads: a committed edit set is immutable; every const function on it is thread-safe.
// The scene and accel are borrowed and must outlive it.
#ifndef DRIFT_REFLECT_EDIT_H
#define DRIFT_REFLECT_EDIT_H

#include "drift/accel.h"
#include "drift/core.h"
#include "drift/math.h"
#include "drift/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

// Limits the file reader and the add functions enforce.
#define DRIFT_EDIT_MAX_CONSTRAINTS 256
#define DRIFT_EDIT_MAX_REGIONS     64

// --- 3x3 ROTATIONS ---

typedef struct drift_mat3 {
    float m[3][3]; // row-major: m[row][column]
} drift_mat3;

static inline drift_mat3 drift_mat3_identity(void)
{
    return (drift_mat3){ { { 1.0f, 0.0f, 0.0f }, { 0.0f, 1.0f, 0.0f }, { 0.0f, 0.0f, 1.0f } } };
}

static inline drift_vec3 drift_mat3_apply(const drift_mat3 *a, drift_vec3 v)
{
    return (drift_vec3){ a->m[0][0] * v.x + a->m[0][1] * v.y + a->m[0][2] * v.z,
                         a->m[1][0] * v.x + a->m[1][1] * v.y + a->m[1][2] * v.z,
                         a->m[2][0] * v.x + a->m[2][1] * v.y + a->m[2][2] * v.z };
}

// The rotation nearest to M in the Frobenius norm, M = U S V^T -> U diag(1, 1, det(U V^T)) V^T
// (the polar factor; Horn 1987), from a Jacobi SVD in double. When M has rank 1 (one
// constraint: the roll about e is undetermined) it is the minimal rotation taking M's right
// singular vector to its left one. M = 0 gives the identity.
drift_mat3 drift_mat3_ortho(double m[3][3]);
// The minimal rotation taking unit a to unit b (axis a x b; a half turn about an axis normal to
// a when b = -a).
drift_mat3 drift_mat3_rotation_between(drift_vec3 a, drift_vec3 b);

// --- EDITS ---

// A surface point where the field is evaluated: its position, and where it lies on the mesh
// (for geodesic distances). mesh DRIFT_INVALID_INDEX: not on a mesh (Euclidean terms only).
typedef struct drift_edit_point {
    drift_vec3 position;
    uint32_t mesh, triangle;
    drift_vec2 barycentric; // of the triangle's vertices 1 and 2
} drift_edit_point;

drift_edit_point drift_edit_point_from_surface(const drift_surface *surface);

typedef struct drift_reflection_constraint {
    uint32_t mesh;     // the mirror's mesh
    drift_vec3 point;  // p_n, the red handle (snapped onto the mesh at commit)
    drift_vec3 target; // g_n, the green handle
    drift_vec3 view;   // the generating view's eye position
} drift_reflection_constraint;

typedef enum drift_edit_region_type {
    DRIFT_EDIT_REGION_EUCLIDEAN = 0, // |q - centre| <= radius, across every object
    DRIFT_EDIT_REGION_GEODESIC,      // distance along mesh `mesh` from centre <= radius
    DRIFT_EDIT_REGION_MASK,          // painted vertices of `mesh` (free-form)
    DRIFT_EDIT_REGION_TYPE_COUNT
} drift_edit_region_type;

// a(q) = 1 - smoothstep(radius, radius + border, d(q)); for masks d is the geodesic distance
// to the nearest painted vertex and radius is 0.
typedef struct drift_reflection_region {
    drift_edit_region_type type;
    drift_vec3 centre;
    float radius, border;
    uint32_t mesh;                 // geodesic and mask regions
    const uint32_t *mask_vertices; // mask: the painted vertex indices of `mesh` (copied)
    uint32_t mask_vertex_count;
} drift_reflection_region;

typedef enum drift_edit_distance {
    DRIFT_EDIT_DISTANCE_EUCLIDEAN = 0, // d(p_n, q) = |p_n - q|
    DRIFT_EDIT_DISTANCE_GEODESIC,      // along p_n's mesh (Euclidean off it)
} drift_edit_distance;

typedef struct drift_reflection_edits drift_reflection_edits;

// Errors: DRIFT_ERR_INVALID_ARGUMENT (uncommitted scene), DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift_reflection_edits_create(drift_context *ctx, const drift_scene *scene,
                                           const drift_accel *accel,
                                           drift_reflection_edits **out_edits);
void drift_reflection_edits_destroy(drift_reflection_edits *edits); // NULL-safe

// Each returns DRIFT_ERR_INVALID_ARGUMENT (logged) for a bad mesh index, a non-finite value,
// a negative radius or border, or a full list. The edits stay uncommitted until _commit.
drift_result drift_reflection_edits_add_constraint(drift_reflection_edits *edits,
                                                   const drift_reflection_constraint *c);
drift_result drift_reflection_edits_add_region(drift_reflection_edits *edits,
                                               const drift_reflection_region *region);
// Removes entry `index` (later ones move down); false when there is none.
bool drift_reflection_edits_remove_constraint(drift_reflection_edits *edits, uint32_t index);
bool drift_reflection_edits_remove_region(drift_reflection_edits *edits, uint32_t index);
void drift_reflection_edits_set_distance(drift_reflection_edits *edits, drift_edit_distance d);

// Derives r_n and e_n (a ray from each constraint's view toward p_n must hit its mesh near p_n:
// p_n snaps to that hit), and the Dijkstra distances of geodesic terms. Errors:
// DRIFT_ERR_INVALID_ARGUMENT (logged) when a red handle cannot be seen from its view.
drift_result drift_reflection_edits_commit(drift_reflection_edits *edits);

uint32_t drift_reflection_edits_constraint_count(const drift_reflection_edits *edits);
uint32_t drift_reflection_edits_region_count(const drift_reflection_edits *edits);
const drift_reflection_constraint *
drift_reflection_edits_constraint(const drift_reflection_edits *edits, uint32_t index);
const drift_reflection_region *drift_reflection_edits_region(const drift_reflection_edits *edits,
                                                             uint32_t index);
// The derived rays of constraint `index` (after commit).
void drift_reflection_edits_constraint_rays(const drift_reflection_edits *edits, uint32_t index,
                                            drift_vec3 *out_r, drift_vec3 *out_e);
drift_edit_distance drift_reflection_edits_distance(const drift_reflection_edits *edits);

// The influence a(q) in [0, 1] of the regions (1 everywhere when there are none).
float drift_reflection_edits_influence(const drift_reflection_edits *edits,
                                       const drift_edit_point *q);
// R(q) and a(q), the view-independent part of the field: the identity and 0 where no
// constraint reaches q. Needs a committed edit set.
void drift_reflection_edits_rotation(const drift_reflection_edits *edits, const drift_edit_point *q,
                                     drift_mat3 *out_rotation, float *out_influence);
// e = R_a r (eq. 7.7 then 7.6) for a rotation and influence from _rotation; r exactly when
// a = 0.
drift_vec3 drift_reflection_edits_apply(const drift_mat3 *rotation, float influence, drift_vec3 r);
// e(q) for the physical reflection r(q): _rotation then _apply.
drift_vec3 drift_reflection_edits_direction(const drift_reflection_edits *edits,
                                            const drift_edit_point *q, drift_vec3 r);
// Aims the glossy and mirror lobes of `bsdf`, made at `surface` and seen along wo, at e(q)
// (drift_bsdf.edited_mirror): the one call every renderer makes at its first specular bounce.
// Nothing changes when edits is NULL or the bsdf has no specular lobe.
void drift_reflection_edits_aim_bsdf(const drift_reflection_edits *edits,
                                     const drift_surface *surface, drift_vec3 wo, drift_bsdf *bsdf);
// The normalised weight w_n / sum_m w_m of constraint n at q among the constraints that reach
// it (0 when n does not).
float drift_reflection_edits_weight(const drift_reflection_edits *edits, const drift_edit_point *q,
                                    uint32_t n);

// Dijkstra over the edge graph of mesh `mesh` (vertices welded by position) from a point on
// triangle `triangle`: out_distances[v] for every vertex of the mesh (INFINITY where
// unreachable). For tests and the viewer's overlay.
drift_result drift_reflection_edits_geodesic(const drift_reflection_edits *edits, uint32_t mesh,
                                             uint32_t triangle, drift_vec3 source,
                                             float *out_distances);

// --- FILES (docs/reflection-editing.md) ---

// Reads an edit file. Errors name the file and line: DRIFT_ERR_IO, DRIFT_ERR_PARSE (bad JSON,
// an unknown key or mesh, a non-finite or out-of-range value), DRIFT_ERR_INVALID_ARGUMENT
// (a handle not seen from its view). The result is committed.
drift_result drift_reflection_edits_load(drift_context *ctx, const drift_scene *scene,
                                         const drift_accel *accel, const char *path,
                                         drift_reflection_edits **out_edits);
// As _load from text in memory; `name` labels messages (the fuzz target's entry).
drift_result drift_reflection_edits_parse(drift_context *ctx, const drift_scene *scene,
                                          const drift_accel *accel, const char *text, size_t length,
                                          const char *name, drift_reflection_edits **out_edits);
// Writes the edits as an edit file (through a temporary file and a rename).
drift_result drift_reflection_edits_save(const drift_reflection_edits *edits, const char *path);

#ifdef __cplusplus
}
#endif
#endif // DRIFT_REFLECT_EDIT_H
