// Closed emissive meshes (scene commit): a mesh emitting from both faces (glTF doubleSided,
// which Blender writes for every mesh) whose surface is closed lights the side the camera is
// on through the faces turned to that side only; the other faces' light stays behind the
// mesh's own surface. So commit makes such a mesh one-sided: the path tracer stops spending
// light samples on faces turned away, and the hybrid frame, whose shadows do not see a
// light's own surface, stops counting them (a glowing ball lit the room from both hemispheres
// of its surface: corpus bl-emissive's direct light was 1.22x the path tracer's).
#include "scene_internal.h"

#include <math.h>
#include <stdlib.h>

// A vertex and its position, sorted by position (x, then y, then z) for welding.
typedef struct weld_vertex {
    float p[3];
    uint32_t v;
} weld_vertex;

static int compare_positions(const void *a, const void *b)
{
    const float *p = ((const weld_vertex *)a)->p, *q = ((const weld_vertex *)b)->p;
    for (int k = 0; k < 3; ++k) {
        if (p[k] != q[k]) {
            return p[k] < q[k] ? -1 : 1;
        }
    }
    return 0;
}

static int compare_edges(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

// Whether mesh m is closed and consistently wound once its vertices are welded by exact
// position (exporters split vertices at uv seams and sharp edges): every directed edge appears
// once and its reverse once. Its signed volume (positive: the triangles' fronts face out) goes
// to out_volume. False when memory runs out.
static bool closed_mesh(drift_context *ctx, const drift_mesh *m, double *out_volume)
{
    uint32_t n = m->vertex_count, t_count = m->triangle_count;
    weld_vertex *order = drift_alloc(ctx, sizeof(weld_vertex) * (n ? n : 1));
    uint32_t *id = drift_alloc(ctx, sizeof(uint32_t) * (n ? n : 1));
    uint64_t *edges = drift_alloc(ctx, sizeof(uint64_t) * 3u * (t_count ? t_count : 1));
    bool closed = order && id && edges && t_count > 0;
    if (closed) {
        for (uint32_t v = 0; v < n; ++v) {
            order[v] = (weld_vertex){
                { m->positions[3u * v], m->positions[3u * v + 1], m->positions[3u * v + 2] }, v
            };
        }
        qsort(order, n, sizeof *order, compare_positions);
        for (uint32_t k = 0; k < n; ++k) {
            bool same = k > 0 && compare_positions(&order[k - 1], &order[k]) == 0;
            id[order[k].v] = same ? id[order[k - 1].v] : order[k].v;
        }
        double volume = 0.0;
        for (uint32_t t = 0; t < t_count; ++t) {
            const uint32_t *tri = m->indices + 3u * t;
            for (int k = 0; k < 3; ++k) {
                edges[3u * t + (uint32_t)k] =
                    (uint64_t)id[tri[k]] << 32 | (uint64_t)id[tri[(k + 1) % 3]];
            }
            double a[3], b[3], c[3];
            for (int k = 0; k < 3; ++k) {
                a[k] = (double)m->positions[3u * tri[0] + (uint32_t)k];
                b[k] = (double)m->positions[3u * tri[1] + (uint32_t)k];
                c[k] = (double)m->positions[3u * tri[2] + (uint32_t)k];
            }
            volume += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                      a[2] * (b[0] * c[1] - b[1] * c[0]);
        }
        *out_volume = volume / 6.0;
        uint32_t e_count = 3u * t_count;
        qsort(edges, e_count, sizeof *edges, compare_edges);
        for (uint32_t e = 0; e < e_count && closed; ++e) {
            uint64_t from = edges[e] >> 32, to = edges[e] & 0xffffffffu;
            uint64_t reverse = to << 32 | from;
            bool twice = e + 1 < e_count && edges[e + 1] == edges[e];
            closed = from != to && !twice &&
                     bsearch(&reverse, edges, e_count, sizeof *edges, compare_edges) != NULL;
        }
    }
    drift_free(ctx, order);
    drift_free(ctx, id);
    drift_free(ctx, edges);
    return closed;
}

// Winding number of a closed mesh about point p (1 or -1 inside, 0 outside): the triangles'
// signed solid angles (Van Oosterom and Strackee 1983) over 4 pi.
static double winding_number(const drift_mesh *m, drift_vec3 p)
{
    double total = 0.0;
    for (uint32_t t = 0; t < m->triangle_count; ++t) {
        const uint32_t *tri = m->indices + 3u * t;
        double v[3][3];
        for (int k = 0; k < 3; ++k) {
            const float *q = m->positions + 3u * tri[k];
            v[k][0] = (double)q[0] - (double)p.x;
            v[k][1] = (double)q[1] - (double)p.y;
            v[k][2] = (double)q[2] - (double)p.z;
        }
        double la = sqrt(v[0][0] * v[0][0] + v[0][1] * v[0][1] + v[0][2] * v[0][2]);
        double lb = sqrt(v[1][0] * v[1][0] + v[1][1] * v[1][1] + v[1][2] * v[1][2]);
        double lc = sqrt(v[2][0] * v[2][0] + v[2][1] * v[2][1] + v[2][2] * v[2][2]);
        double det = v[0][0] * (v[1][1] * v[2][2] - v[1][2] * v[2][1]) -
                     v[0][1] * (v[1][0] * v[2][2] - v[1][2] * v[2][0]) +
                     v[0][2] * (v[1][0] * v[2][1] - v[1][1] * v[2][0]);
        double ab = v[0][0] * v[1][0] + v[0][1] * v[1][1] + v[0][2] * v[1][2];
        double bc = v[1][0] * v[2][0] + v[1][1] * v[2][1] + v[1][2] * v[2][2];
        double ca = v[2][0] * v[0][0] + v[2][1] * v[0][1] + v[2][2] * v[0][2];
        total += 2.0 * atan2(det, la * lb * lc + ab * lc + bc * la + ca * lb);
    }
    return total / (4.0 * (double)DRIFT_PI);
}

bool drift__closed_emitter_front_only(const drift_scene *scene, uint32_t mesh)
{
    const drift_mesh *m = &scene->meshes[mesh];
    double volume = 0.0;
    if (!closed_mesh(scene->ctx, m, &volume) || volume == 0.0) {
        return false;
    }
    bool camera_inside = fabs(winding_number(m, scene->camera.position)) > 0.5;
    return camera_inside == (volume < 0.0);
}
