// Geodesic distance as in the thesis (§7.5.2): Dijkstra along the mesh's edges from the
// source, per vertex, interpolated across triangles by the barycentrics (Gouraud). The edge
// metric overestimates the true geodesic by at most sqrt(2) on a regular grid and assumes a
// dense mesh. Vertices at the same position are welded first, so UV or normal seams (split
// vertices) do not cut the graph.
#include "reflect_edit/reflect_edit_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static drift_vec3 vertex_position(const drift_mesh *mesh, uint32_t v)
{
    const float *p = mesh->positions + 3 * (size_t)v;
    return drift_vec3_make(p[0], p[1], p[2]);
}

// qsort has no user pointer: the mesh being sorted (only ever one at a time, under the
// edit set's single-threaded build).
static _Thread_local const float *sort_positions;

static int compare_position(const void *a, const void *b)
{
    const float *p = sort_positions + 3 * (size_t) * (const uint32_t *)a;
    const float *q = sort_positions + 3 * (size_t) * (const uint32_t *)b;
    for (int k = 0; k < 3; ++k) {
        if (p[k] != q[k]) {
            return p[k] < q[k] ? -1 : 1;
        }
    }
    return 0;
}

void drift__edge_graph_free(drift_context *ctx, drift__edge_graph *graph)
{
    drift_free(ctx, graph->weld);
    drift_free(ctx, graph->row_start);
    drift_free(ctx, graph->neighbours);
    drift_free(ctx, graph->lengths);
    *graph = (drift__edge_graph){ 0 };
}

static drift_result build_graph(drift_context *ctx, const drift_mesh *mesh, drift__edge_graph *g)
{
    uint32_t n = mesh->vertex_count;
    size_t edges = 6 * (size_t)mesh->triangle_count; // each triangle: 3 edges, both ways
    uint32_t *order = drift_alloc(ctx, n * sizeof(uint32_t));
    g->weld = drift_alloc(ctx, n * sizeof(uint32_t));
    g->row_start = drift_alloc(ctx, ((size_t)n + 1) * sizeof(uint32_t));
    g->neighbours = drift_alloc(ctx, edges * sizeof(uint32_t));
    g->lengths = drift_alloc(ctx, edges * sizeof(float));
    if (!order || !g->weld || !g->row_start || !g->neighbours || !g->lengths) {
        drift_free(ctx, order);
        drift__edge_graph_free(ctx, g);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t v = 0; v < n; ++v) {
        order[v] = v;
    }
    sort_positions = mesh->positions;
    qsort(order, n, sizeof(uint32_t), compare_position);
    uint32_t nodes = 0;
    for (uint32_t i = 0; i < n; ++i) {
        if (i > 0 && compare_position(&order[i - 1], &order[i]) != 0) {
            nodes++;
        }
        g->weld[order[i]] = nodes;
    }
    g->node_count = n ? nodes + 1 : 0;
    drift_free(ctx, order);
    // Count, then fill, the rows (a counting sort of the directed edges by their source).
    for (uint32_t t = 0; t < mesh->triangle_count; ++t) {
        const uint32_t *tri = mesh->indices + 3 * (size_t)t;
        for (int k = 0; k < 3; ++k) {
            g->row_start[g->weld[tri[k]] + 1] += 2;
        }
    }
    for (uint32_t v = 0; v < g->node_count; ++v) {
        g->row_start[v + 1] += g->row_start[v];
    }
    uint32_t *fill = drift_alloc(ctx, ((size_t)g->node_count + 1) * sizeof(uint32_t));
    if (!fill) {
        drift__edge_graph_free(ctx, g);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    memcpy(fill, g->row_start, g->node_count * sizeof(uint32_t));
    for (uint32_t t = 0; t < mesh->triangle_count; ++t) {
        const uint32_t *tri = mesh->indices + 3 * (size_t)t;
        for (int k = 0; k < 3; ++k) {
            uint32_t a = tri[k], b = tri[(k + 1) % 3];
            float len = drift_vec3_length(
                drift_vec3_sub(vertex_position(mesh, a), vertex_position(mesh, b)));
            uint32_t wa = g->weld[a], wb = g->weld[b];
            g->neighbours[fill[wa]] = wb;
            g->lengths[fill[wa]++] = len;
            g->neighbours[fill[wb]] = wa;
            g->lengths[fill[wb]++] = len;
        }
    }
    drift_free(ctx, fill);
    return DRIFT_OK;
}

const drift__edge_graph *drift__edge_graph_get(drift_reflection_edits *edits, uint32_t mesh)
{
    if (!edits->graphs) {
        edits->graphs =
            drift_alloc(edits->ctx, edits->scene->mesh_count * sizeof(drift__edge_graph));
        if (!edits->graphs) {
            return NULL;
        }
    }
    drift__edge_graph *g = &edits->graphs[mesh];
    if (!g->weld && build_graph(edits->ctx, &edits->scene->meshes[mesh], g) != DRIFT_OK) {
        return NULL;
    }
    return g;
}

// --- DIJKSTRA (binary heap, lazy deletion) ---

typedef struct heap_entry {
    float distance;
    uint32_t node;
} heap_entry;

typedef struct heap {
    heap_entry *items;
    size_t count, capacity;
} heap;

static bool heap_push(drift_context *ctx, heap *h, heap_entry e)
{
    if (h->count == h->capacity) {
        size_t capacity = h->capacity ? 2 * h->capacity : 256;
        heap_entry *items = drift_realloc(ctx, h->items, h->capacity * sizeof(heap_entry),
                                          capacity * sizeof(heap_entry));
        if (!items) {
            return false;
        }
        h->items = items;
        h->capacity = capacity;
    }
    size_t i = h->count++;
    while (i > 0 && h->items[(i - 1) / 2].distance > e.distance) {
        h->items[i] = h->items[(i - 1) / 2];
        i = (i - 1) / 2;
    }
    h->items[i] = e;
    return true;
}

static heap_entry heap_pop(heap *h)
{
    heap_entry top = h->items[0], last = h->items[--h->count];
    size_t i = 0;
    for (;;) {
        size_t child = 2 * i + 1;
        if (child >= h->count) {
            break;
        }
        if (child + 1 < h->count && h->items[child + 1].distance < h->items[child].distance) {
            child++;
        }
        if (h->items[child].distance >= last.distance) {
            break;
        }
        h->items[i] = h->items[child];
        i = child;
    }
    if (h->count > 0) {
        h->items[i] = last;
    }
    return top;
}

drift_result drift__dijkstra(drift_context *ctx, const drift__edge_graph *graph,
                             uint32_t vertex_count, const uint32_t *seeds,
                             const float *seed_distances, uint32_t seed_count, float *out)
{
    float *node_distance = drift_alloc(ctx, ((size_t)graph->node_count + 1) * sizeof(float));
    if (!node_distance) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t v = 0; v < graph->node_count; ++v) {
        node_distance[v] = INFINITY;
    }
    heap h = { 0 };
    drift_result result = DRIFT_OK;
    for (uint32_t i = 0; i < seed_count; ++i) {
        uint32_t node = graph->weld[seeds[i]];
        if (seed_distances[i] < node_distance[node]) {
            node_distance[node] = seed_distances[i];
            if (!heap_push(ctx, &h, (heap_entry){ seed_distances[i], node })) {
                result = DRIFT_ERR_OUT_OF_MEMORY;
            }
        }
    }
    while (result == DRIFT_OK && h.count > 0) {
        heap_entry top = heap_pop(&h);
        if (top.distance > node_distance[top.node]) {
            continue; // a stale entry: the node was settled nearer
        }
        for (uint32_t k = graph->row_start[top.node]; k < graph->row_start[top.node + 1]; ++k) {
            uint32_t next = graph->neighbours[k];
            float d = top.distance + graph->lengths[k];
            if (d < node_distance[next]) {
                node_distance[next] = d;
                if (!heap_push(ctx, &h, (heap_entry){ d, next })) {
                    result = DRIFT_ERR_OUT_OF_MEMORY;
                    break;
                }
            }
        }
    }
    for (uint32_t v = 0; v < vertex_count; ++v) {
        out[v] = node_distance[graph->weld[v]];
    }
    drift_free(ctx, h.items);
    drift_free(ctx, node_distance);
    return result;
}

float drift__vertex_distance(const drift_scene *scene, uint32_t mesh, const float *distances,
                             const drift_edit_point *q)
{
    if (q->mesh != mesh || q->triangle >= scene->meshes[mesh].triangle_count) {
        return INFINITY;
    }
    const uint32_t *tri = scene->meshes[mesh].indices + 3 * (size_t)q->triangle;
    float b1 = q->barycentric.x, b2 = q->barycentric.y, b0 = 1.0f - b1 - b2;
    return b0 * distances[tri[0]] + b1 * distances[tri[1]] + b2 * distances[tri[2]];
}

drift_result drift_reflection_edits_geodesic(const drift_reflection_edits *edits, uint32_t mesh,
                                             uint32_t triangle, drift_vec3 source,
                                             float *out_distances)
{
    if (!edits || mesh >= edits->scene->mesh_count ||
        triangle >= edits->scene->meshes[mesh].triangle_count || !out_distances) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    // The graph cache is private state that changes nothing a caller can see.
    drift_reflection_edits *mutable_edits = (drift_reflection_edits *)edits;
    const drift__edge_graph *g = drift__edge_graph_get(mutable_edits, mesh);
    if (!g) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    const drift_mesh *m = &edits->scene->meshes[mesh];
    const uint32_t *tri = m->indices + 3 * (size_t)triangle;
    float start[3];
    for (int k = 0; k < 3; ++k) {
        start[k] = drift_vec3_length(drift_vec3_sub(vertex_position(m, tri[k]), source));
    }
    return drift__dijkstra(edits->ctx, g, m->vertex_count, tri, start, 3, out_distances);
}
