// glTF node animation played on a loaded scene (docs/temporal.md, "glTF animation"): the
// meshes and punctual lights whose nodes (or their parents) a channel moves are posed at a
// time t by the change of their node's world transform since rest, M(t) = W(t) W_rest^-1,
// applied to the rest-pose vertices the loader placed (world space, kept here): positions by
// M, normals by M's cofactor, tangents by M; a mirroring M swaps two corners of each triangle
// so the faces keep facing out, as the loader does. The scene is then committed again, which
// moves its emissive triangles' lights with them. Evaluation is scene_gltf_anim.c's.
#include "drift/scene_io.h"
#include "scene_gltf_anim.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct affine {
    double m[12]; // row-major 3 x 4: the linear part and the translation
} affine;

typedef struct moving_mesh {
    uint32_t mesh;
    int node;
    affine rest_inverse;  // W_rest^-1
    drift__mat4 rest;     // W_rest as evaluated (a pose equal to it is the rest pose)
    drift__mat4 posed;    // the world transform it stands at now
    drift__mat4 previous; // and at the pose before (drift_scene_animation_motion)
    bool mirrored;        // its triangles are wound against the rest pose's (det M < 0)
    float *positions;     // rest pose, 3 a vertex
    float *normals;       // rest pose, or NULL
    float *tangents;      // rest pose, 4 a vertex, or NULL
} moving_mesh;

typedef struct moving_light {
    uint32_t light;
    int node;
    affine rest_inverse;
    drift__mat4 rest, posed;
    drift_light at_rest;
} moving_light;

struct drift_scene_animation {
    drift_context *ctx;
    drift_scene *scene;
    gltf_anim file;
    moving_mesh *meshes;
    uint32_t mesh_count;
    moving_light *lights;
    uint32_t light_count;
    bool camera_moves;
    bool *node_moves; // per node of the file: a channel moves it or a parent
};

static affine affine_of(const drift__mat4 *t)
{
    affine a;
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 4; ++c) {
            a.m[r * 4 + c] = (double)t->m[r * 4 + c];
        }
    }
    return a;
}

static double affine_det(const affine *a)
{
    const double *m = a->m;
    return m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) +
           m[2] * (m[4] * m[9] - m[5] * m[8]);
}

// The inverse of an affine transform; false when its linear part is singular.
static bool affine_inverse(const affine *a, affine *out)
{
    const double *m = a->m;
    double det = affine_det(a);
    if (!(fabs(det) > 1e-30) || !isfinite(det)) {
        return false;
    }
    double inv[9] = { m[5] * m[10] - m[6] * m[9], m[2] * m[9] - m[1] * m[10],
                      m[1] * m[6] - m[2] * m[5],  m[6] * m[8] - m[4] * m[10],
                      m[0] * m[10] - m[2] * m[8], m[2] * m[4] - m[0] * m[6],
                      m[4] * m[9] - m[5] * m[8],  m[1] * m[8] - m[0] * m[9],
                      m[0] * m[5] - m[1] * m[4] };
    for (int r = 0; r < 3; ++r) {
        double t = 0.0;
        for (int c = 0; c < 3; ++c) {
            out->m[r * 4 + c] = inv[r * 3 + c] / det;
            t -= out->m[r * 4 + c] * m[c * 4 + 3];
        }
        out->m[r * 4 + 3] = t;
    }
    return true;
}

static affine affine_mul(const affine *a, const affine *b)
{
    affine o;
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 4; ++c) {
            double v = c == 3 ? a->m[r * 4 + 3] : 0.0;
            for (int k = 0; k < 3; ++k) {
                v += a->m[r * 4 + k] * b->m[k * 4 + c];
            }
            o.m[r * 4 + c] = v;
        }
    }
    return o;
}

static void apply_point(const affine *a, const float *p, float *out)
{
    for (int r = 0; r < 3; ++r) {
        out[r] = (float)(a->m[r * 4] * (double)p[0] + a->m[r * 4 + 1] * (double)p[1] +
                         a->m[r * 4 + 2] * (double)p[2] + a->m[r * 4 + 3]);
    }
}

// The linear part times v (cof: the cofactor matrix instead), normalized; false when it is
// zero or not finite.
static bool apply_direction(const double *lin, int stride, const float *v, float *out)
{
    double d[3], len = 0.0;
    for (int r = 0; r < 3; ++r) {
        d[r] = lin[r * stride] * (double)v[0] + lin[r * stride + 1] * (double)v[1] +
               lin[r * stride + 2] * (double)v[2];
        len += d[r] * d[r];
    }
    len = sqrt(len);
    if (!(len > 0.0) || !isfinite(len)) {
        return false;
    }
    for (int r = 0; r < 3; ++r) {
        out[r] = (float)(d[r] / len);
    }
    return true;
}

static void cofactor(const affine *a, double c[9])
{
    const double *m = a->m;
    c[0] = m[5] * m[10] - m[6] * m[9];
    c[1] = m[6] * m[8] - m[4] * m[10];
    c[2] = m[4] * m[9] - m[5] * m[8];
    c[3] = m[2] * m[9] - m[1] * m[10];
    c[4] = m[0] * m[10] - m[2] * m[8];
    c[5] = m[1] * m[8] - m[0] * m[9];
    c[6] = m[1] * m[6] - m[2] * m[5];
    c[7] = m[2] * m[4] - m[0] * m[6];
    c[8] = m[0] * m[5] - m[1] * m[4];
}

static bool same_matrix(const drift__mat4 *a, const drift__mat4 *b)
{
    return memcmp(a->m, b->m, sizeof a->m) == 0;
}

static float *copy_floats(drift_context *ctx, const float *from, size_t count)
{
    float *to = from ? drift_alloc(ctx, count * sizeof(float)) : NULL;
    if (to) {
        memcpy(to, from, count * sizeof(float));
    }
    return to;
}

// W_rest and its inverse for nodes[node]; false (warned) when the rest pose is singular.
static bool rest_of(drift_scene_animation *s, int node, drift__mat4 *rest, affine *inverse)
{
    if (drift__gltf_node_world(&s->file, node, 0.0, true, rest)) {
        affine w = affine_of(rest);
        if (affine_inverse(&w, inverse)) {
            return true;
        }
    }
    drift_log(s->ctx, DRIFT_LOG_WARNING, DRIFT_ERR_UNSUPPORTED, s->file.path, 0,
              "nodes[%d]: its rest transform is singular (a zero scale) or its parents form a "
              "cycle: what it holds is not animated",
              node);
    return false;
}

static drift_result add_meshes(drift_scene_animation *s)
{
    drift_scene *scene = s->scene;
    s->meshes = drift_alloc(s->ctx, ((size_t)scene->mesh_count + 1) * sizeof(moving_mesh));
    if (!s->meshes) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t i = 0; i < scene->mesh_count; ++i) {
        const drift_mesh *m = &scene->meshes[i];
        int node = m->node == DRIFT_INVALID_INDEX ? -1 : (int)m->node;
        if (node < 0 || node >= s->file.node_count || !s->node_moves[node]) {
            continue;
        }
        moving_mesh mm = { .mesh = i, .node = node };
        if (!rest_of(s, node, &mm.rest, &mm.rest_inverse)) {
            continue;
        }
        mm.posed = mm.previous = mm.rest;
        size_t nv = m->vertex_count;
        mm.positions = copy_floats(s->ctx, m->positions, 3 * nv);
        mm.normals = copy_floats(s->ctx, m->normals, 3 * nv);
        mm.tangents = copy_floats(s->ctx, m->tangents, 4 * nv);
        s->meshes[s->mesh_count++] = mm;
        if (!mm.positions || (m->normals && !mm.normals) || (m->tangents && !mm.tangents)) {
            return DRIFT_ERR_OUT_OF_MEMORY;
        }
    }
    return DRIFT_OK;
}

static void add_lights(drift_scene_animation *s)
{
    const drift_scene *scene = s->scene;
    for (uint32_t i = 0; i < scene->light_count; ++i) {
        const drift_light *l = &scene->lights[i];
        int node = l->node == DRIFT_INVALID_INDEX ? -1 : (int)l->node;
        // Emissive triangles follow their mesh (commit remakes them).
        bool punctual = l->type == DRIFT_LIGHT_POINT || l->type == DRIFT_LIGHT_SPOT ||
                        l->type == DRIFT_LIGHT_DIRECTIONAL;
        if (!punctual || node < 0 || node >= s->file.node_count || !s->node_moves[node]) {
            continue;
        }
        moving_light ml = { .light = i, .node = node, .at_rest = *l };
        if (rest_of(s, node, &ml.rest, &ml.rest_inverse)) {
            ml.posed = ml.rest;
            s->lights[s->light_count++] = ml;
        }
    }
}

// Nodes with a mesh that move but hold none of the scene's meshes: assimp's graph and the
// file's parted (drift__gltf_child_node), so they render at rest.
static void warn_unmatched(const drift_scene_animation *s)
{
    bool *placed = drift_alloc(s->ctx, (size_t)s->file.node_count + 1);
    if (!placed) {
        return;
    }
    memset(placed, 0, (size_t)s->file.node_count + 1);
    for (uint32_t i = 0; i < s->scene->mesh_count; ++i) {
        uint32_t n = s->scene->meshes[i].node;
        if (n < (uint32_t)s->file.node_count) {
            placed[n] = true;
        }
    }
    int unmatched = 0, first = -1;
    for (int n = 0; n < s->file.node_count; ++n) {
        if (s->file.nodes[n].has_mesh && s->node_moves[n] && !placed[n]) {
            first = unmatched++ == 0 ? n : first;
        }
    }
    drift_free(s->ctx, placed);
    if (unmatched > 0) {
        drift_log(s->ctx, DRIFT_LOG_WARNING, DRIFT_ERR_UNSUPPORTED, s->file.path, 0,
                  "%d moving node(s) with a mesh (the first: nodes[%d]) were not matched to the "
                  "meshes loaded: they render at rest",
                  unmatched, first);
    }
}

void drift_scene_animation_destroy(drift_scene_animation *s)
{
    if (!s) {
        return;
    }
    for (uint32_t i = 0; s->meshes && i < s->mesh_count; ++i) {
        drift_free(s->ctx, s->meshes[i].positions);
        drift_free(s->ctx, s->meshes[i].normals);
        drift_free(s->ctx, s->meshes[i].tangents);
    }
    drift_free(s->ctx, s->meshes);
    drift_free(s->ctx, s->lights);
    drift_free(s->ctx, s->node_moves);
    drift__gltf_anim_close(&s->file);
    drift_free(s->ctx, s);
}

drift_result drift_scene_animation_from_gltf(drift_context *ctx, const char *path,
                                             drift_scene *scene, drift_scene_animation **out)
{
    if (!out) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out = NULL;
    if (!ctx || !path || !scene || !scene->committed) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_scene_animation *s = drift_alloc(ctx, sizeof *s);
    if (!s) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    *s = (drift_scene_animation){ .ctx = ctx, .scene = scene };
    s->file = (gltf_anim){ .ctx = ctx, .level = DRIFT_LOG_ERROR, .path = path };
    drift_result r = drift__gltf_anim_open(&s->file);
    if (r == DRIFT_OK) {
        s->node_moves = drift__gltf_moving_nodes(&s->file);
        r = s->node_moves ? DRIFT_OK : DRIFT_ERR_OUT_OF_MEMORY;
    }
    if (r == DRIFT_OK) {
        r = add_meshes(s);
    }
    if (r == DRIFT_OK) {
        s->lights = drift_alloc(ctx, ((size_t)scene->light_count + 1) * sizeof(moving_light));
        r = s->lights ? DRIFT_OK : DRIFT_ERR_OUT_OF_MEMORY;
    }
    if (r == DRIFT_OK) {
        add_lights(s);
        warn_unmatched(s);
        s->camera_moves = drift__gltf_camera_moves(&s->file);
    }
    if (r != DRIFT_OK || s->mesh_count + s->light_count == 0) {
        drift_scene_animation_destroy(s);
        return r;
    }
    *out = s;
    return DRIFT_OK;
}

// The mesh's vertices at M = world · W_rest^-1 (rest bits at rest); false when not finite.
static bool pose_mesh(drift_scene *scene, moving_mesh *mm, const drift__mat4 *world)
{
    drift_mesh *m = &scene->meshes[mm->mesh];
    size_t nv = m->vertex_count;
    bool at_rest = same_matrix(world, &mm->rest);
    affine w = affine_of(world);
    affine move = affine_mul(&w, &mm->rest_inverse);
    double det = affine_det(&move);
    bool mirrored = !at_rest && det < 0.0;
    if (at_rest) {
        memcpy(m->positions, mm->positions, 3 * nv * sizeof(float));
        if (m->normals) {
            memcpy(m->normals, mm->normals, 3 * nv * sizeof(float));
        }
        if (m->tangents) {
            memcpy(m->tangents, mm->tangents, 4 * nv * sizeof(float));
        }
    } else {
        double cof[9];
        cofactor(&move, cof);
        float sign = det < 0.0 ? -1.0f : 1.0f;
        for (size_t v = 0; v < nv; ++v) {
            apply_point(&move, mm->positions + 3 * v, m->positions + 3 * v);
            for (int k = 0; k < 3; ++k) {
                if (!isfinite(m->positions[3 * v + (size_t)k])) {
                    return false;
                }
            }
            if (m->normals && apply_direction(cof, 3, mm->normals + 3 * v, m->normals + 3 * v)) {
                for (int k = 0; k < 3; ++k) {
                    m->normals[3 * v + (size_t)k] *= sign;
                }
            }
            if (m->tangents) {
                apply_direction(move.m, 4, mm->tangents + 4 * v, m->tangents + 4 * v);
                m->tangents[4 * v + 3] = sign * mm->tangents[4 * v + 3];
            }
        }
    }
    if (mirrored != mm->mirrored) {
        for (uint32_t t = 0; t < m->triangle_count; ++t) {
            uint32_t *tri = m->indices + 3 * (size_t)t;
            uint32_t b = tri[1];
            tri[1] = tri[2];
            tri[2] = b;
        }
        mm->mirrored = mirrored;
    }
    mm->posed = *world;
    return true;
}

static bool pose_light(drift_scene *scene, moving_light *ml, const drift__mat4 *world)
{
    drift_light *l = &scene->lights[ml->light];
    drift_light rest = ml->at_rest;
    ml->posed = *world;
    if (same_matrix(world, &ml->rest)) {
        l->position = rest.position;
        l->direction = rest.direction;
        return true;
    }
    affine w = affine_of(world);
    affine move = affine_mul(&w, &ml->rest_inverse);
    float p[3] = { rest.position.x, rest.position.y, rest.position.z }, q[3];
    float d[3] = { rest.direction.x, rest.direction.y, rest.direction.z }, e[3];
    apply_point(&move, p, q);
    l->position = drift_vec3_make(q[0], q[1], q[2]);
    if (rest.type != DRIFT_LIGHT_POINT) {
        if (!apply_direction(move.m, 4, d, e)) {
            return false;
        }
        l->direction = drift_vec3_make(e[0], e[1], e[2]);
    }
    return drift_vec3_is_finite(l->position);
}

drift_result drift_scene_animation_pose(drift_scene_animation *s, double time, bool *out_moved)
{
    if (out_moved) {
        *out_moved = false;
    }
    if (!s || !isfinite(time)) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    bool moved = false, ok = true;
    for (uint32_t i = 0; i < s->mesh_count; ++i) {
        s->meshes[i].previous = s->meshes[i].posed;
    }
    for (uint32_t i = 0; ok && i < s->mesh_count; ++i) {
        moving_mesh *mm = &s->meshes[i];
        drift__mat4 world;
        ok = drift__gltf_node_world(&s->file, mm->node, time, false, &world);
        if (ok && !same_matrix(&world, &mm->posed)) {
            ok = pose_mesh(s->scene, mm, &world);
            moved = true;
        }
    }
    for (uint32_t i = 0; ok && i < s->light_count; ++i) {
        moving_light *ml = &s->lights[i];
        drift__mat4 world;
        ok = drift__gltf_node_world(&s->file, ml->node, time, false, &world);
        if (ok && !same_matrix(&world, &ml->posed)) {
            ok = pose_light(s->scene, ml, &world);
            moved = true;
        }
    }
    if (!ok) {
        // Back to rest, so the scene stays valid.
        for (uint32_t i = 0; i < s->mesh_count; ++i) {
            pose_mesh(s->scene, &s->meshes[i], &s->meshes[i].rest);
        }
        for (uint32_t i = 0; i < s->light_count; ++i) {
            pose_light(s->scene, &s->lights[i], &s->lights[i].rest);
        }
    }
    drift_result r = moved ? drift_scene_commit(s->scene) : DRIFT_OK;
    if (!ok) {
        drift_log(s->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, s->file.path, 0,
                  "the animation's pose at t = %g s is degenerate (a zero scale) or not finite",
                  time);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    if (out_moved) {
        *out_moved = moved;
    }
    return r;
}

drift_result drift_scene_animation_motion(const drift_scene_animation *s, float *out,
                                          uint32_t mesh_count)
{
    if (!s || !out || mesh_count != s->scene->mesh_count) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    for (uint32_t m = 0; m < mesh_count; ++m) {
        float *a = out + 12 * (size_t)m;
        memset(a, 0, 12 * sizeof(float));
        a[0] = a[5] = a[10] = 1.0f;
    }
    for (uint32_t i = 0; i < s->mesh_count; ++i) {
        const moving_mesh *mm = &s->meshes[i];
        if (same_matrix(&mm->previous, &mm->posed)) {
            continue;
        }
        affine now = affine_of(&mm->posed), now_inverse, was = affine_of(&mm->previous);
        if (!affine_inverse(&now, &now_inverse)) {
            continue; // a collapsed pose: no motion to tell
        }
        affine back = affine_mul(&was, &now_inverse);
        for (int k = 0; k < 12; ++k) {
            out[12 * (size_t)mm->mesh + (size_t)k] = (float)back.m[k];
        }
    }
    return DRIFT_OK;
}

bool drift_scene_animation_camera_moves(const drift_scene_animation *s)
{
    return s && s->camera_moves;
}

uint32_t drift_scene_animation_mesh_count(const drift_scene_animation *s)
{
    return s ? s->mesh_count : 0;
}

uint32_t drift_scene_animation_light_count(const drift_scene_animation *s)
{
    return s ? s->light_count : 0;
}
