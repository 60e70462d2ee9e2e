// Private state of an edit set, shared by field.c (the rotation field), geodesic.c (the mesh
// edge graph and Dijkstra) and edit_file.c (reading and writing edit files).
#ifndef DRIFT_REFLECT_EDIT_INTERNAL_H
#define DRIFT_REFLECT_EDIT_INTERNAL_H

#include "drift/reflect_edit.h"

// The edge graph of one mesh, vertices welded by position (so seams do not cut it):
// compressed rows of (neighbour, edge length) per welded vertex.
typedef struct drift__edge_graph {
    uint32_t *weld;       // mesh vertex -> welded vertex
    uint32_t node_count;  // welded vertices
    uint32_t *row_start;  // node_count + 1
    uint32_t *neighbours; // row_start[node_count]
    float *lengths;       // same
} drift__edge_graph;

// A constraint with what commit derives from it.
typedef struct drift__constraint {
    drift_reflection_constraint desc;
    drift_edit_point at; // p_n where the ray from the view hit its mesh
    drift_vec3 r, e;     // eq. 7.1 and normalize(g - p)
    float *distances;    // geodesic weights: per mesh vertex of desc.mesh (else NULL)
    uint64_t reached;    // bit k: the constraint lies inside region k, a_k(p_n) > 0
} drift__constraint;

typedef struct drift__region {
    drift_reflection_region desc; // mask_vertices points at `mask`
    uint32_t *mask;
    float *distances;    // geodesic and mask: per mesh vertex of desc.mesh
    drift_edit_point at; // geodesic: where the centre lies on the mesh
} drift__region;

struct drift_reflection_edits {
    drift_context *ctx;
    const drift_scene *scene;
    const drift_accel *accel;
    drift_edit_distance distance;
    drift__constraint constraints[DRIFT_EDIT_MAX_CONSTRAINTS];
    uint32_t constraint_count;
    drift__region regions[DRIFT_EDIT_MAX_REGIONS];
    uint32_t region_count;
    drift__edge_graph *graphs; // per mesh, built on first use (NULL rows until then)
    bool committed;
    int32_t failed_constraint; // the constraint the last commit could not place, or -1
};

// The graph of mesh `mesh`, built on first use.
const drift__edge_graph *drift__edge_graph_get(drift_reflection_edits *edits, uint32_t mesh);
void drift__edge_graph_free(drift_context *ctx, drift__edge_graph *graph);
// Multi-source Dijkstra: seed_count mesh vertices with start distances; out per mesh vertex.
drift_result drift__dijkstra(drift_context *ctx, const drift__edge_graph *graph,
                             uint32_t vertex_count, const uint32_t *seeds,
                             const float *seed_distances, uint32_t seed_count, float *out);
// The per-vertex distances interpolated at q (q on `mesh`); INFINITY off the mesh.
float drift__vertex_distance(const drift_scene *scene, uint32_t mesh, const float *distances,
                             const drift_edit_point *q);

#endif
