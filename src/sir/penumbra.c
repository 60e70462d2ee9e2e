// SIR's shadow error (paper section 5): where a shadow map's point-light lookup may be wrong
// because the area light is partly hidden, in the spirit of Guennebaud et al. 2006: blockers
// in the cone from the receiver to the light, and an unblocked tap in their backprojected
// region. It searches the frame's shadow maps texel by texel (raster/shadow_map_internal.h).
#include "raster/shadow_map_internal.h"
#include "sir/sir.h"

#include <math.h>

// Taps a side of the square grids below (the blocker search repeats it at shrinking radii).
#define PENUMBRA_GRID 8
// Levels of the blocker search at most this many texels in radius test texels, not taps.
#define TEXEL_LEVEL 2.0f

typedef struct penumbra_search {
    const drift_shadow_map *map;
    const drift_shadow_receiver *rec;
    float L;           // light size for the cone (the map's radius unless the query is tighter)
    bool hierarchical; // prove regions blocker-free from the min-depth mip before tapping
    bool texel_levels; // test texels instead of taps at the finest levels
} penumbra_search;

// Offset radius within which a blocker at depth z can hide part of the light from the
// receiver: the cone from the receiver to the light (radius L) seen from the centre,
// L (d_r - z) / (d_r z) (directional: L (d_r - z)), plus a texel for the tap's own footprint.
static float blocker_cone(const penumbra_search *s, float z)
{
    float L = s->L, d_r = s->rec->depth;
    float cone =
        s->map->directional ? L * (d_r - z) : (z > 0.0f ? L * (d_r - z) / (d_r * z) : INFINITY);
    return cone + s->rec->texel;
}

// The cone test inverted: a blocker at offset radius o passes it only at depth <= this
// (INFINITY when every depth passes, within a texel of the receiver's direction).
static float cone_depth_bound(const penumbra_search *s, float o)
{
    float excess = o - s->rec->texel, L = s->L, d_r = s->rec->depth;
    if (!(excess > 0.0f)) {
        return INFINITY;
    }
    return s->map->directional ? d_r - excess / L : L * d_r / (excess * d_r + L);
}

// Least depth stored in any texel a tap with ox in [x0, x1], oy in [y0, y1] can read. Cube
// maps: the rectangle of directions dir + ox t1 + oy t2 is convex, and so is its central
// projection onto a face plane when every corner is in front of it; the corners' bounding box
// then holds every tap that lands on the face (padded two texels for rounding). When all four
// corners land on one face, so does the whole rectangle (its image is convex, and so is the
// face's square). A face the rectangle straddles is read whole; one behind every corner gets
// no tap.
static float region_min_depth(const penumbra_search *s, float x0, float y0, float x1, float y1)
{
    const drift_shadow_map *map = s->map;
    const drift_shadow_receiver *rec = s->rec;
    int32_t last = map->size - 1;
    if (map->directional) {
        float fx0 = (rec->x + x0) / map->texel_size - 2.0f,
              fx1 = (rec->x + x1) / map->texel_size + 2.0f;
        float fy0 = (rec->y + y0) / map->texel_size - 2.0f,
              fy1 = (rec->y + y1) / map->texel_size + 2.0f;
        if (fx1 < 0.0f || fy1 < 0.0f || fx0 > (float)last || fy0 > (float)last) {
            return INFINITY;
        }
        int32_t ix0 = fx0 < 0.0f ? 0 : (int32_t)fx0, iy0 = fy0 < 0.0f ? 0 : (int32_t)fy0;
        int32_t ix1 = fx1 > (float)last ? last : (int32_t)fx1;
        int32_t iy1 = fy1 > (float)last ? last : (int32_t)fy1;
        return drift_shadow_map_min_depth_rect(map, 0, ix0, iy0, ix1, iy1);
    }
    drift_vec3 corner[4];
    int faces[4];
    for (int k = 0; k < 4; ++k) {
        corner[k] = drift_vec3_fma(drift_vec3_fma(rec->dir, rec->t1, (k & 1) ? x1 : x0), rec->t2,
                                   (k & 2) ? y1 : y0);
        faces[k] = drift_shadow_map_major_face(corner[k]);
    }
    bool one_face = faces[0] == faces[1] && faces[0] == faces[2] && faces[0] == faces[3];
    float best = INFINITY, pad = 4.0f / (float)map->size;
    for (int f = one_face ? faces[0] : 0; f < (one_face ? faces[0] + 1 : CUBE_FACES); ++f) {
        int slot = map->face_slot[f];
        if (slot < 0) {
            continue;
        }
        int a = f / 2;
        float sign = f % 2 == 0 ? 1.0f : -1.0f;
        int in_front = 0;
        float u0 = INFINITY, u1 = -INFINITY, v0 = INFINITY, v1 = -INFINITY;
        for (int k = 0; k < 4; ++k) {
            float along = sign * drift_shadow_map_axis(corner[k], a);
            if (along > 0.0f) {
                ++in_front;
                float u = drift_shadow_map_axis(corner[k], (a + 1) % 3) / along;
                float v = drift_shadow_map_axis(corner[k], (a + 2) % 3) / along;
                u0 = fminf(u0, u);
                u1 = fmaxf(u1, u);
                v0 = fminf(v0, v);
                v1 = fmaxf(v1, v);
            }
        }
        if (in_front == 0) {
            continue;
        }
        int32_t tx0 = 0, tx1 = last, ty0 = 0, ty1 = last;
        if (in_front == 4) {
            if (u0 - pad > 1.0f || u1 + pad < -1.0f || v0 - pad > 1.0f || v1 + pad < -1.0f) {
                continue;
            }
            tx0 = drift_shadow_map_texel_index(u0 - pad, map->size);
            tx1 = drift_shadow_map_texel_index(u1 + pad, map->size);
            ty0 = drift_shadow_map_texel_index(v0 - pad, map->size);
            ty1 = drift_shadow_map_texel_index(v1 + pad, map->size);
        }
        best = fminf(best, drift_shadow_map_min_depth_rect(map, slot, tx0, ty0, tx1, ty1));
    }
    return best;
}

// The texels a square of taps (|ox|, |oy| <= r) can read, when it lands on one face (cube) or
// on the map (orthographic): slot and inclusive texel rectangle. False when it spans faces.
typedef struct texel_rect {
    int face, slot;
    int32_t x0, y0, x1, y1;
} texel_rect;

static bool square_texels(const penumbra_search *s, float r, texel_rect *out)
{
    const drift_shadow_map *map = s->map;
    const drift_shadow_receiver *rec = s->rec;
    int32_t last = map->size - 1;
    if (map->directional) {
        float fx0 = (rec->x - r) / map->texel_size, fx1 = (rec->x + r) / map->texel_size;
        float fy0 = (rec->y - r) / map->texel_size, fy1 = (rec->y + r) / map->texel_size;
        if (!(fx0 >= 0.0f && fy0 >= 0.0f && fx1 < (float)map->size && fy1 < (float)map->size)) {
            return false; // partly outside the map: taps there see nothing, rectangle clipped
        }
        *out = (texel_rect){ 0, 0, (int32_t)fx0, (int32_t)fy0, (int32_t)fx1, (int32_t)fy1 };
        return out->x1 <= last && out->y1 <= last;
    }
    drift_vec3 corner[4];
    int face = -1;
    for (int k = 0; k < 4; ++k) {
        corner[k] = drift_vec3_fma(drift_vec3_fma(rec->dir, rec->t1, (k & 1) ? r : -r), rec->t2,
                                   (k & 2) ? r : -r);
        int f = drift_shadow_map_major_face(corner[k]);
        if (face >= 0 && f != face) {
            return false;
        }
        face = f;
    }
    if (map->face_slot[face] < 0) {
        return false;
    }
    int a = face / 2;
    float u0 = INFINITY, u1 = -INFINITY, v0 = INFINITY, v1 = -INFINITY;
    for (int k = 0; k < 4; ++k) {
        float major = fabsf(drift_shadow_map_axis(corner[k], a));
        float u = drift_shadow_map_axis(corner[k], (a + 1) % 3) / major,
              v = drift_shadow_map_axis(corner[k], (a + 2) % 3) / major;
        u0 = fminf(u0, u);
        u1 = fmaxf(u1, u);
        v0 = fminf(v0, v);
        v1 = fmaxf(v1, v);
    }
    *out = (texel_rect){ face,
                         map->face_slot[face],
                         drift_shadow_map_texel_index(u0, map->size),
                         drift_shadow_map_texel_index(v0, map->size),
                         drift_shadow_map_texel_index(u1, map->size),
                         drift_shadow_map_texel_index(v1, map->size) };
    return true;
}

// The finest levels, a couple of texels wide, would put many of their 64 taps in each texel:
// instead every texel the square can read is tested once, against the receiver plane alone
// (the cone test at these offsets accepts nearly any depth; skipping it only adds blockers).
// -1 when the square spans faces (the caller taps it).
static int32_t search_texels(const penumbra_search *s, float radius, bool first_only,
                             float *out_nearest)
{
    texel_rect rect;
    if (!square_texels(s, radius, &rect)) {
        return -1;
    }
    const drift_shadow_map *map = s->map;
    size_t size = (size_t)map->size;
    int32_t blockers = 0;
    for (int32_t y = rect.y0; y <= rect.y1; ++y) {
        for (int32_t x = rect.x0; x <= rect.x1; ++x) {
            drift_shadow_texel t = {
                .stored = map->depth[((size_t)rect.slot * size + (size_t)y) * size + (size_t)x],
                .face = rect.face,
                .x = x,
                .y = y
            };
            if (t.stored >= drift_shadow_map_receiver_at(map, s->rec, &t) - s->rec->bias) {
                continue;
            }
            blockers++;
            *out_nearest = fminf(*out_nearest, t.stored);
            if (first_only) {
                return blockers;
            }
        }
    }
    return blockers;
}

// Whether the mip proves that no tap of a group finds a blocker: every texel the group can
// read (offsets in the square of half width `reach`) is deeper than the cone allows at the
// group's nearest tap (rounding slack on the side of tapping). *lower is a known lower bound on
// those depths (from a larger square); raised to the square's least depth when it is read.
static bool proven_free(const penumbra_search *s, float reach, float nearest_offset, float *lower)
{
    float bound = cone_depth_bound(s, nearest_offset) * 1.001f;
    if (!(bound < INFINITY)) {
        return false;
    }
    if (*lower > bound) {
        return true;
    }
    *lower = fmaxf(*lower, region_min_depth(s, -reach, -reach, reach, reach));
    return *lower > bound;
}

// Taps of a grid of PENUMBRA_GRID^2 over the square of half width `radius` that see a blocker
// (a nearer surface inside the cone to the light: Guennebaud's backprojection test of whether
// its shadow can reach the receiver), and the nearest blocker's depth; with `first_only`, stops
// at the first. The hierarchical search skips the inner 4 x 4 block and the outer ring when
// the mip proves them free (finer groups cost more in proofs than they save in taps), so it
// finds exactly the exhaustive search's blockers. A texel just found lit is not tested again
// (the same texel, the same answer).
static int32_t search_level(const penumbra_search *s, float radius, bool first_only, float *lower,
                            float *out_nearest)
{
    *out_nearest = INFINITY;
    // Tap (i, j) is at odd multiples of step: (2i + 1 - GRID) step.
    const float step = radius / (float)PENUMBRA_GRID;
    if (s->texel_levels && radius <= TEXEL_LEVEL * s->rec->texel) {
        int32_t blockers = search_texels(s, radius, first_only, out_nearest);
        if (blockers >= 0) {
            return blockers;
        }
    }
    bool skip_inner = false, skip_outer = false;
    if (s->hierarchical) {
        // Inner taps (1 or 3 steps out each way) are at least sqrt(2) steps from the centre and
        // read within 4; outer taps at least 5 steps away, within the radius. *lower bounds
        // the depths over the whole square and leaves bounding those of the inner block, which
        // holds the next level's square (a third of the radius).
        skip_outer = proven_free(s, radius, 5.0f * step, lower);
        skip_inner = proven_free(s, 4.0f * step, 1.41421356f * step, lower);
        if (skip_inner && skip_outer) {
            return 0;
        }
    }
    int32_t blockers = 0;
    drift_shadow_texel lit = { .face = -2 }; // the last texel found lit
    for (int32_t j = 0; j < PENUMBRA_GRID; ++j) {
        for (int32_t i = 0; i < PENUMBRA_GRID; ++i) {
            int32_t mx = 2 * i + 1 - PENUMBRA_GRID, my = 2 * j + 1 - PENUMBRA_GRID;
            bool inner = mx >= -3 && mx <= 3 && my >= -3 && my <= 3;
            if (inner ? skip_inner : skip_outer) {
                continue;
            }
            float ox = step * (float)mx, oy = step * (float)my;
            drift_shadow_texel t = drift_shadow_map_tap_lands(s->map, s->rec, ox, oy);
            if (t.face == lit.face && t.x == lit.x && t.y == lit.y) {
                continue;
            }
            // The cone test first: it needs only the stored depth, and most taps fail it.
            if (sqrtf(ox * ox + oy * oy) > blocker_cone(s, t.stored)) {
                continue;
            }
            if (t.stored >= drift_shadow_map_receiver_at(s->map, s->rec, &t) - s->rec->bias) {
                lit = t;
                continue;
            }
            blockers++;
            *out_nearest = fminf(*out_nearest, t.stored);
            if (first_only) {
                return blockers;
            }
        }
    }
    return blockers;
}

// Whether every tap of the grid over the square of half width `radius` is behind a nearer
// surface (the umbra test).
static bool all_blocked(const penumbra_search *s, float radius)
{
    for (int32_t j = 0; j < PENUMBRA_GRID; ++j) {
        for (int32_t i = 0; i < PENUMBRA_GRID; ++i) {
            float ox = radius * (2.0f * ((float)i + 0.5f) / PENUMBRA_GRID - 1.0f);
            float oy = radius * (2.0f * ((float)j + 0.5f) / PENUMBRA_GRID - 1.0f);
            if (drift_shadow_map_tap_lit(s->rec, drift_shadow_map_tap(s->map, s->rec, ox, oy))) {
                return false;
            }
        }
    }
    return true;
}

float drift_shadow_map_penumbra(const drift_shadow_map *map, drift_vec3 p, drift_vec3 n)
{
    return drift_shadow_map_penumbra_query(map, p, n, &(drift_penumbra_query){ 0 });
}

float drift_shadow_map_penumbra_query(const drift_shadow_map *map, drift_vec3 p, drift_vec3 n,
                                      const drift_penumbra_query *query)
{
    if (!(map->radius > 0.0f)) {
        return 0.0f; // a point light casts no penumbra
    }
    drift_shadow_receiver rec = drift_shadow_map_receiver(map, p, n);
    float L = query->light_size > 0.0f ? fminf(query->light_size, map->radius) : map->radius;
    penumbra_search s = { .map = map,
                          .rec = &rec,
                          .L = L,
                          .hierarchical = !query->exhaustive,
                          .texel_levels = !query->taps_only };
    float d_r = rec.depth;
    // Blocker search over the whole cone from the receiver to the light, with the near plane
    // at the light's own size (PCSS trims it to a quarter of the way: here nothing is trimmed,
    // the estimate must be conservative).
    float search;
    if (map->directional) {
        search = L * d_r;
    } else {
        float near = fmaxf(L, 1e-3f * d_r);
        search = d_r > near ? L * (d_r - near) / (d_r * near) : 0.0f;
    }
    search = drift_clampf(search, rec.texel, drift_shadow_map_max_radius(map));
    drift_shadow_tap centre = drift_shadow_map_tap(map, &rec, 0.0f, 0.0f);
    bool centre_blocked = !drift_shadow_map_tap_lit(&rec, centre);
    // Blockers near the receiver have narrow cones: a grid spaced for the whole search region
    // steps over them. Search again at each third of the radius, down to two texels. With the
    // centre visible, one blocker anywhere decides (penumbra).
    int32_t blockers = 0;
    float nearest = INFINITY, lower = -INFINITY;
    for (float r = search; blockers == 0; r *= 1.0f / 3.0f) {
        blockers += search_level(&s, r, !centre_blocked, &lower, &nearest);
        if (r < 2.0f * rec.texel) {
            break;
        }
    }
    if (!centre_blocked) {
        // Fully lit when nothing lies between the receiver and any point of the light; blockers
        // in the cone with the light's centre visible: partly covered.
        return blockers == 0 ? 0.0f : 1.0f;
    }
    nearest = fminf(nearest, centre.stored);
    // Backprojection bound: the nearest blocker (closest to the light) spreads the widest
    // penumbra, L (d_r - d_b) / d_b at the receiver. When every tap of that region blocks,
    // the light is hidden from the whole region: umbra.
    float region = map->directional ? L * (d_r - nearest)
                                    : (nearest > 0.0f ? L * (d_r - nearest) / (nearest * d_r)
                                                      : drift_shadow_map_max_radius(map));
    region = drift_clampf(region, rec.texel, drift_shadow_map_max_radius(map));
    return all_blocked(&s, region) ? 0.0f : 1.0f;
}
