// The moving-least-squares rotation field (thesis §7.4): per surface point q the rotation
// R(q) = ortho(sum_n w_n e_n r_n^T) with w_n = 1 / d(p_n, q)^2, blended by the regions'
// influence a(q) (eq. 7.7). Near a constraint its weight dominates; at d = 0 the fit becomes
// the constrained one (R r_n = e_n exactly, the roll about r_n still fitted to the others),
// which is the limit of the weighted fit, so the field is interpolating and continuous there.
#include "reflect_edit/reflect_edit_internal.h"

#include <math.h>
#include <string.h>

// A constraint whose normalised weight exceeds this takes the constrained fit.
#define DOMINANT_WEIGHT (1.0 - 1e-6)

drift_edit_point drift_edit_point_from_surface(const drift_surface *s)
{
    return (drift_edit_point){ .position = s->position,
                               .mesh = s->mesh,
                               .triangle = s->triangle,
                               .barycentric = s->barycentric };
}

void drift_reflection_edits_aim_bsdf(const drift_reflection_edits *edits,
                                     const drift_surface *surface, drift_vec3 wo, drift_bsdf *bsdf)
{
    if (!edits || drift_vec3_is_zero(bsdf->specular)) {
        return;
    }
    drift_edit_point q = drift_edit_point_from_surface(surface);
    bsdf->edited_mirror =
        drift_reflection_edits_direction(edits, &q, drift_vec3_reflect(wo, bsdf->frame.z));
}

// --- LIFETIME AND EDITING ---

drift_result drift_reflection_edits_create(drift_context *ctx, const drift_scene *scene,
                                           const drift_accel *accel,
                                           drift_reflection_edits **out_edits)
{
    if (!out_edits) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out_edits = NULL;
    if (!scene || !scene->committed || !accel) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_reflection_edits *e = drift_alloc(ctx, sizeof(drift_reflection_edits));
    if (!e) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    e->ctx = ctx;
    e->scene = scene;
    e->accel = accel;
    e->committed = true; // an empty edit set is the identity
    *out_edits = e;
    return DRIFT_OK;
}

static void free_constraint(drift_context *ctx, drift__constraint *c)
{
    drift_free(ctx, c->distances);
    c->distances = NULL;
}

static void free_region(drift_context *ctx, drift__region *r)
{
    drift_free(ctx, r->mask);
    drift_free(ctx, r->distances);
    r->mask = NULL;
    r->distances = NULL;
}

void drift_reflection_edits_destroy(drift_reflection_edits *edits)
{
    if (!edits) {
        return;
    }
    drift_context *ctx = edits->ctx;
    for (uint32_t i = 0; i < edits->constraint_count; ++i) {
        free_constraint(ctx, &edits->constraints[i]);
    }
    for (uint32_t i = 0; i < edits->region_count; ++i) {
        free_region(ctx, &edits->regions[i]);
    }
    if (edits->graphs) {
        for (uint32_t m = 0; m < edits->scene->mesh_count; ++m) {
            drift__edge_graph_free(ctx, &edits->graphs[m]);
        }
    }
    drift_free(ctx, edits->graphs);
    drift_free(ctx, edits);
}

static drift_result reject(const drift_reflection_edits *edits, const char *what)
{
    drift_log(edits->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
              "reflection edits: %s", what);
    return DRIFT_ERR_INVALID_ARGUMENT;
}

drift_result drift_reflection_edits_add_constraint(drift_reflection_edits *edits,
                                                   const drift_reflection_constraint *c)
{
    if (!edits || !c) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    if (edits->constraint_count >= DRIFT_EDIT_MAX_CONSTRAINTS) {
        return reject(edits, "too many constraints");
    }
    if (c->mesh >= edits->scene->mesh_count) {
        return reject(edits, "constraint on a mesh the scene does not have");
    }
    if (!drift_vec3_is_finite(c->point) || !drift_vec3_is_finite(c->target) ||
        !drift_vec3_is_finite(c->view)) {
        return reject(edits, "constraint with a non-finite point, target or view");
    }
    edits->constraints[edits->constraint_count++] = (drift__constraint){ .desc = *c };
    edits->committed = false;
    return DRIFT_OK;
}

drift_result drift_reflection_edits_add_region(drift_reflection_edits *edits,
                                               const drift_reflection_region *region)
{
    if (!edits || !region) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    if (edits->region_count >= DRIFT_EDIT_MAX_REGIONS) {
        return reject(edits, "too many regions");
    }
    if ((unsigned)region->type >= DRIFT_EDIT_REGION_TYPE_COUNT) {
        return reject(edits, "region of an unknown type");
    }
    if (!drift_vec3_is_finite(region->centre) || !isfinite(region->radius) ||
        !isfinite(region->border) || region->radius < 0.0f || region->border < 0.0f) {
        return reject(edits, "region with a non-finite centre or a negative radius or border");
    }
    bool on_mesh = region->type != DRIFT_EDIT_REGION_EUCLIDEAN;
    if (on_mesh && region->mesh >= edits->scene->mesh_count) {
        return reject(edits, "region on a mesh the scene does not have");
    }
    drift__region r = { .desc = *region };
    if (region->type == DRIFT_EDIT_REGION_MASK) {
        if (region->mask_vertex_count == 0 || !region->mask_vertices) {
            return reject(edits, "mask region without vertices");
        }
        uint32_t vertex_count = edits->scene->meshes[region->mesh].vertex_count;
        for (uint32_t i = 0; i < region->mask_vertex_count; ++i) {
            if (region->mask_vertices[i] >= vertex_count) {
                return reject(edits, "mask vertex out of range");
            }
        }
        r.mask = drift_alloc(edits->ctx, region->mask_vertex_count * sizeof(uint32_t));
        if (!r.mask) {
            return DRIFT_ERR_OUT_OF_MEMORY;
        }
        memcpy(r.mask, region->mask_vertices, region->mask_vertex_count * sizeof(uint32_t));
        r.desc.mask_vertices = r.mask;
    } else {
        r.desc.mask_vertices = NULL;
        r.desc.mask_vertex_count = 0;
    }
    edits->regions[edits->region_count++] = r;
    edits->committed = false;
    return DRIFT_OK;
}

bool drift_reflection_edits_remove_constraint(drift_reflection_edits *edits, uint32_t index)
{
    if (!edits || index >= edits->constraint_count) {
        return false;
    }
    free_constraint(edits->ctx, &edits->constraints[index]);
    memmove(&edits->constraints[index], &edits->constraints[index + 1],
            (edits->constraint_count - index - 1) * sizeof(drift__constraint));
    edits->constraint_count--;
    edits->committed = false;
    return true;
}

bool drift_reflection_edits_remove_region(drift_reflection_edits *edits, uint32_t index)
{
    if (!edits || index >= edits->region_count) {
        return false;
    }
    free_region(edits->ctx, &edits->regions[index]);
    memmove(&edits->regions[index], &edits->regions[index + 1],
            (edits->region_count - index - 1) * sizeof(drift__region));
    edits->region_count--;
    edits->committed = false;
    return true;
}

void drift_reflection_edits_set_distance(drift_reflection_edits *edits, drift_edit_distance d)
{
    edits->distance = d;
    edits->committed = false;
}

uint32_t drift_reflection_edits_constraint_count(const drift_reflection_edits *edits)
{
    return edits ? edits->constraint_count : 0;
}

uint32_t drift_reflection_edits_region_count(const drift_reflection_edits *edits)
{
    return edits ? edits->region_count : 0;
}

const drift_reflection_constraint *
drift_reflection_edits_constraint(const drift_reflection_edits *edits, uint32_t index)
{
    return index < edits->constraint_count ? &edits->constraints[index].desc : NULL;
}

const drift_reflection_region *drift_reflection_edits_region(const drift_reflection_edits *edits,
                                                             uint32_t index)
{
    return index < edits->region_count ? &edits->regions[index].desc : NULL;
}

void drift_reflection_edits_constraint_rays(const drift_reflection_edits *edits, uint32_t index,
                                            drift_vec3 *out_r, drift_vec3 *out_e)
{
    *out_r = edits->constraints[index].r;
    *out_e = edits->constraints[index].e;
}

drift_edit_distance drift_reflection_edits_distance(const drift_reflection_edits *edits)
{
    return edits->distance;
}

// --- COMMIT ---

static float region_influence(const drift_reflection_edits *edits, const drift__region *r,
                              const drift_edit_point *q);

// Where the ray from the constraint's view toward its red handle meets the mirror, and r_n.
static drift_result place_constraint(drift_reflection_edits *edits, uint32_t index)
{
    drift__constraint *c = &edits->constraints[index];
    drift_vec3 to_point = drift_vec3_sub(c->desc.point, c->desc.view);
    float length = drift_vec3_length(to_point);
    float tolerance = 1e-2f * drift_scene_extent(edits->scene);
    drift_ray ray = { .origin = c->desc.view,
                      .dir = drift_vec3_scale(to_point, 1.0f / fmaxf(length, 1e-30f)),
                      .tmin = 0.0f,
                      .tmax = length + tolerance };
    drift_hit hit;
    if (!(length > 0.0f) || !drift_accel_intersect(edits->accel, &ray, &hit) ||
        hit.mesh != c->desc.mesh) {
        drift_log(edits->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "reflection edits: constraint %u: its point is not seen on mesh '%s' from its "
                  "view",
                  index, edits->scene->meshes[c->desc.mesh].name);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_surface s = drift_scene_surface(edits->scene, &ray, &hit);
    if (drift_vec3_length(drift_vec3_sub(s.position, c->desc.point)) > tolerance) {
        drift_log(edits->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "reflection edits: constraint %u: its point is hidden from its view", index);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    c->at = drift_edit_point_from_surface(&s);
    c->r = drift_vec3_normalize(drift_vec3_reflect(drift_vec3_neg(ray.dir), s.ns));
    drift_vec3 to_target = drift_vec3_sub(c->desc.target, s.position);
    if (!(drift_vec3_length(to_target) > 0.0f)) {
        drift_log(edits->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "reflection edits: constraint %u: its target is its point", index);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    c->e = drift_vec3_normalize(to_target);
    return DRIFT_OK;
}

static uint32_t nearest_vertex(const drift_mesh *mesh, drift_vec3 p)
{
    uint32_t best = 0;
    float best_d = INFINITY;
    for (uint32_t v = 0; v < mesh->vertex_count; ++v) {
        const float *q = mesh->positions + 3 * (size_t)v;
        float d = drift_vec3_length(drift_vec3_sub(drift_vec3_make(q[0], q[1], q[2]), p));
        if (d < best_d) {
            best_d = d;
            best = v;
        }
    }
    return best;
}

static drift_result region_distances(drift_reflection_edits *edits, drift__region *r)
{
    if (r->desc.type == DRIFT_EDIT_REGION_EUCLIDEAN) {
        return DRIFT_OK;
    }
    const drift_mesh *mesh = &edits->scene->meshes[r->desc.mesh];
    const drift__edge_graph *g = drift__edge_graph_get(edits, r->desc.mesh);
    drift_free(edits->ctx, r->distances);
    r->distances = drift_alloc(edits->ctx, mesh->vertex_count * sizeof(float));
    if (!g || !r->distances) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    if (r->desc.type == DRIFT_EDIT_REGION_MASK) {
        float *zeros = drift_alloc(edits->ctx, r->desc.mask_vertex_count * sizeof(float));
        if (!zeros) {
            return DRIFT_ERR_OUT_OF_MEMORY;
        }
        drift_result res = drift__dijkstra(edits->ctx, g, mesh->vertex_count, r->mask, zeros,
                                           r->desc.mask_vertex_count, r->distances);
        drift_free(edits->ctx, zeros);
        return res;
    }
    // Geodesic: from the vertex nearest the centre (the thesis snaps it so, §7.5.2).
    uint32_t seed = nearest_vertex(mesh, r->desc.centre);
    const float *p = mesh->positions + 3 * (size_t)seed;
    float start =
        drift_vec3_length(drift_vec3_sub(drift_vec3_make(p[0], p[1], p[2]), r->desc.centre));
    return drift__dijkstra(edits->ctx, g, mesh->vertex_count, &seed, &start, 1, r->distances);
}

drift_result drift_reflection_edits_commit(drift_reflection_edits *edits)
{
    if (!edits) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    edits->committed = false;
    edits->failed_constraint = -1;
    for (uint32_t i = 0; i < edits->constraint_count; ++i) {
        drift__constraint *c = &edits->constraints[i];
        drift_result r = place_constraint(edits, i);
        if (r != DRIFT_OK) {
            edits->failed_constraint = (int32_t)i;
            return r;
        }
        free_constraint(edits->ctx, c);
        if (edits->distance == DRIFT_EDIT_DISTANCE_GEODESIC) {
            c->distances = drift_alloc(edits->ctx, edits->scene->meshes[c->desc.mesh].vertex_count *
                                                       sizeof(float));
            if (!c->distances) {
                return DRIFT_ERR_OUT_OF_MEMORY;
            }
            r = drift_reflection_edits_geodesic(edits, c->desc.mesh, c->at.triangle, c->at.position,
                                                c->distances);
            if (r != DRIFT_OK) {
                return r;
            }
        }
    }
    for (uint32_t k = 0; k < edits->region_count; ++k) {
        drift_result r = region_distances(edits, &edits->regions[k]);
        if (r != DRIFT_OK) {
            return r;
        }
    }
    for (uint32_t n = 0; n < edits->constraint_count; ++n) {
        drift__constraint *c = &edits->constraints[n];
        c->reached = 0;
        for (uint32_t k = 0; k < edits->region_count; ++k) {
            if (region_influence(edits, &edits->regions[k], &c->at) > 0.0f) {
                c->reached |= (uint64_t)1 << k;
            }
        }
    }
    edits->committed = true;
    return DRIFT_OK;
}

// --- THE FIELD ---

static float smoothstep(float edge0, float edge1, float x)
{
    if (x <= edge0) {
        return 0.0f;
    }
    if (x >= edge1) {
        return 1.0f;
    }
    float t = (x - edge0) / (edge1 - edge0);
    return t * t * (3.0f - 2.0f * t);
}

static float region_influence(const drift_reflection_edits *edits, const drift__region *r,
                              const drift_edit_point *q)
{
    float d;
    if (r->desc.type == DRIFT_EDIT_REGION_EUCLIDEAN) {
        d = drift_vec3_length(drift_vec3_sub(q->position, r->desc.centre));
    } else {
        d = drift__vertex_distance(edits->scene, r->desc.mesh, r->distances, q);
    }
    return 1.0f - smoothstep(r->desc.radius, r->desc.radius + r->desc.border, d);
}

float drift_reflection_edits_influence(const drift_reflection_edits *edits,
                                       const drift_edit_point *q)
{
    if (edits->region_count == 0) {
        return 1.0f;
    }
    float a = 0.0f;
    for (uint32_t k = 0; k < edits->region_count; ++k) {
        a = fmaxf(a, region_influence(edits, &edits->regions[k], q));
    }
    return a;
}

// d(p_n, q)^2: Euclidean, or along p_n's mesh for geodesic weights (in p_n's own triangle,
// where the vertex distances do not resolve it, the straight line).
static double distance_squared(const drift_reflection_edits *edits, const drift__constraint *c,
                               const drift_edit_point *q)
{
    drift_vec3 d = drift_vec3_sub(q->position, c->at.position);
    double euclid = (double)drift_vec3_dot(d, d);
    if (!c->distances || q->mesh != c->at.mesh || q->triangle == c->at.triangle) {
        return euclid;
    }
    double g = (double)drift__vertex_distance(edits->scene, c->at.mesh, c->distances, q);
    return isfinite(g) ? fmax(g * g, euclid) : euclid;
}

// R r_n = e_n exactly, the roll phi about r_n maximising tr(R^T M_others):
// R = R0 F Rot_z(phi) F^T with R0 the minimal rotation r_n -> e_n and F = [x y r_n].
static drift_mat3 constrained_fit(const drift__constraint *c, double others[3][3])
{
    drift_mat3 r0 = drift_mat3_rotation_between(c->r, c->e);
    drift_frame f = drift_frame_from_normal(c->r);
    const drift_vec3 basis[2] = { f.x, f.y };
    double cm[2][2]; // basis_i^T R0^T M_o basis_j = (R0 basis_i)^T M_o basis_j
    for (int i = 0; i < 2; ++i) {
        drift_vec3 a = drift_mat3_apply(&r0, basis[i]);
        for (int j = 0; j < 2; ++j) {
            drift_vec3 b = basis[j];
            double mb[3];
            for (int k = 0; k < 3; ++k) {
                mb[k] = others[k][0] * (double)b.x + others[k][1] * (double)b.y +
                        others[k][2] * (double)b.z;
            }
            cm[i][j] = (double)a.x * mb[0] + (double)a.y * mb[1] + (double)a.z * mb[2];
        }
    }
    double phi = atan2(cm[1][0] - cm[0][1], cm[0][0] + cm[1][1]);
    double cs = cos(phi), sn = sin(phi);
    // Rot = r r^T + cos (x x^T + y y^T) + sin (y x^T - x y^T), then R0 Rot.
    double rot[3][3];
    const double x[3] = { (double)f.x.x, (double)f.x.y, (double)f.x.z },
                 y[3] = { (double)f.y.x, (double)f.y.y, (double)f.y.z },
                 z[3] = { (double)f.z.x, (double)f.z.y, (double)f.z.z };
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            rot[i][j] =
                z[i] * z[j] + cs * (x[i] * x[j] + y[i] * y[j]) + sn * (y[i] * x[j] - x[i] * y[j]);
        }
    }
    double out[3][3];
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            out[i][j] = 0.0;
            for (int k = 0; k < 3; ++k) {
                out[i][j] += (double)r0.m[i][k] * rot[k][j];
            }
        }
    }
    return drift_mat3_ortho(out); // a rotation already: this only removes float round-off
}

// Whether constraint n reaches region k (or, with no regions, every point).
static bool reaches(const drift_reflection_edits *edits, int region, uint32_t n)
{
    return region < 0 || (edits->constraints[n].reached >> region & 1u);
}

// R of one region's constraints at q (eq. 7.5); false when none reach it.
static bool region_rotation(const drift_reflection_edits *edits, int region,
                            const drift_edit_point *q, drift_mat3 *out)
{
    double w[DRIFT_EDIT_MAX_CONSTRAINTS];
    double sum = 0.0, largest = 0.0;
    int dominant = -1;
    for (uint32_t n = 0; n < edits->constraint_count; ++n) {
        w[n] = 0.0;
        if (!reaches(edits, region, n)) {
            continue;
        }
        double d2 = distance_squared(edits, &edits->constraints[n], q);
        w[n] = d2 > 1e-30 ? 1.0 / d2 : (double)INFINITY;
        if (w[n] > largest) {
            largest = w[n];
            dominant = (int)n;
        }
        sum += w[n];
    }
    if (dominant < 0) {
        return false;
    }
    double m[3][3] = { { 0.0 } };
    bool constrained = isinf(largest) || largest >= DOMINANT_WEIGHT * sum;
    double scale = constrained ? 1.0 : 1.0 / sum;
    for (uint32_t n = 0; n < edits->constraint_count; ++n) {
        if (w[n] == 0.0 || (constrained && (int)n == dominant) || isinf(w[n])) {
            continue;
        }
        const drift__constraint *c = &edits->constraints[n];
        double wn = w[n] * scale;
        const double e[3] = { (double)c->e.x, (double)c->e.y, (double)c->e.z },
                     r[3] = { (double)c->r.x, (double)c->r.y, (double)c->r.z };
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j) {
                m[i][j] += wn * e[i] * r[j];
            }
        }
    }
    *out = constrained ? constrained_fit(&edits->constraints[dominant], m) : drift_mat3_ortho(m);
    return true;
}

void drift_reflection_edits_rotation(const drift_reflection_edits *edits, const drift_edit_point *q,
                                     drift_mat3 *out_rotation, float *out_influence)
{
    *out_rotation = drift_mat3_identity();
    *out_influence = 0.0f;
    if (!edits || edits->constraint_count == 0) {
        return;
    }
    DRIFT_CHECK(edits->committed);
    if (edits->region_count == 0) {
        if (region_rotation(edits, -1, q, out_rotation)) {
            *out_influence = 1.0f;
        }
        return;
    }
    // Regions are independent: each fits its own constraints; where they overlap their
    // rotations blend by a_k(q) and are re-orthonormalised.
    double blend[3][3] = { { 0.0 } };
    float a_max = 0.0f;
    int contributors = 0;
    drift_mat3 last = drift_mat3_identity();
    for (uint32_t k = 0; k < edits->region_count; ++k) {
        float a = region_influence(edits, &edits->regions[k], q);
        drift_mat3 rk;
        if (!(a > 0.0f) || !region_rotation(edits, (int)k, q, &rk)) {
            continue;
        }
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j) {
                blend[i][j] += (double)a * (double)rk.m[i][j];
            }
        }
        a_max = fmaxf(a_max, a);
        contributors++;
        last = rk;
    }
    if (contributors == 0) {
        return;
    }
    *out_rotation = contributors == 1 ? last : drift_mat3_ortho(blend);
    *out_influence = fminf(1.0f, a_max);
}

drift_vec3 drift_reflection_edits_apply(const drift_mat3 *rotation, float influence, drift_vec3 r)
{
    if (!(influence > 0.0f)) {
        return r; // a = 0: the identity, exactly
    }
    if (influence >= 1.0f) {
        return drift_vec3_normalize(drift_mat3_apply(rotation, r));
    }
    // R_a = ortho(a R + (1 - a) r r^T) (eq. 7.7).
    double m[3][3];
    const double rv[3] = { (double)r.x, (double)r.y, (double)r.z };
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            m[i][j] = (double)influence * (double)rotation->m[i][j] +
                      (1.0 - (double)influence) * rv[i] * rv[j];
        }
    }
    drift_mat3 ra = drift_mat3_ortho(m);
    return drift_vec3_normalize(drift_mat3_apply(&ra, r));
}

drift_vec3 drift_reflection_edits_direction(const drift_reflection_edits *edits,
                                            const drift_edit_point *q, drift_vec3 r)
{
    drift_mat3 rotation;
    float a;
    drift_reflection_edits_rotation(edits, q, &rotation, &a);
    return drift_reflection_edits_apply(&rotation, a, r);
}

float drift_reflection_edits_weight(const drift_reflection_edits *edits, const drift_edit_point *q,
                                    uint32_t n)
{
    if (n >= edits->constraint_count) {
        return 0.0f;
    }
    int region = -1;
    if (edits->region_count > 0) {
        for (uint32_t k = 0; k < edits->region_count && region < 0; ++k) {
            region = reaches(edits, (int)k, n) ? (int)k : -1;
        }
        if (region < 0) {
            return 0.0f;
        }
    }
    double sum = 0.0, mine = 0.0;
    for (uint32_t m = 0; m < edits->constraint_count; ++m) {
        if (!reaches(edits, region, m)) {
            continue;
        }
        double d2 = distance_squared(edits, &edits->constraints[m], q);
        double w = d2 > 1e-30 ? 1.0 / d2 : 1e300;
        sum += w;
        mine = m == n ? w : mine;
    }
    return sum > 0.0 ? (float)(mine / sum) : 0.0f;
}
