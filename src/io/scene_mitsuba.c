// Mitsuba 0.5/0.6 scene files (.xml), and Mitsuba 3's brought to that form by
// scene_mitsuba3.c, the subset Bitterli's "Rendering Resources" use, read
// with expat into a small element tree and then mapped onto drift's scene (the mapping table
// is in docs/scene-format.md). Unsupported elements are named in a warning with their line;
// malformed XML, unknown shape types and bad values are errors naming the file and line.
#include "scene_mitsuba_internal.h"

#include <expat.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define XML_MAX_DEPTH 64

typedef struct xml_reader {
    drift_context *ctx;
    XML_Parser parser;
    xml_node *root, *current;
    int depth;
    bool out_of_memory, too_deep;
} xml_reader;

static char *dup_string(drift_context *ctx, const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = drift_alloc(ctx, n);
    if (d) {
        memcpy(d, s, n);
    }
    return d;
}

static void free_node(drift_context *ctx, xml_node *n)
{
    while (n) {
        xml_node *next = n->next;
        free_node(ctx, n->first);
        if (n->attrs) {
            for (char **a = n->attrs; *a; ++a) {
                drift_free(ctx, *a);
            }
        }
        drift_free(ctx, n->attrs);
        drift_free(ctx, n->name);
        drift_free(ctx, n);
        n = next;
    }
}

static void XMLCALL on_start(void *user, const XML_Char *name, const XML_Char **attrs)
{
    xml_reader *x = user;
    if (x->out_of_memory || x->too_deep) {
        return;
    }
    if (++x->depth > XML_MAX_DEPTH) {
        x->too_deep = true;
        return;
    }
    xml_node *n = drift_alloc(x->ctx, sizeof(*n));
    size_t count = 0;
    while (attrs[count]) {
        count++;
    }
    if (!n) {
        x->out_of_memory = true;
        return;
    }
    *n = (xml_node){ .name = dup_string(x->ctx, name),
                     .attrs = drift_alloc(x->ctx, (count + 1) * sizeof(char *)),
                     .line = (int)XML_GetCurrentLineNumber(x->parser),
                     .parent = x->current };
    if (n->attrs) {
        for (size_t i = 0; i < count; ++i) {
            n->attrs[i] = dup_string(x->ctx, attrs[i]);
            x->out_of_memory = x->out_of_memory || !n->attrs[i];
        }
        n->attrs[count] = NULL;
    }
    x->out_of_memory = x->out_of_memory || !n->name || !n->attrs;
    if (x->current) {
        if (x->current->last) {
            x->current->last->next = n;
        } else {
            x->current->first = n;
        }
        x->current->last = n;
    } else if (!x->root) {
        x->root = n;
    } else {
        free_node(x->ctx, n); // cannot happen: expat allows one root
        return;
    }
    x->current = n;
}

static void XMLCALL on_end(void *user, const XML_Char *name)
{
    xml_reader *x = user;
    (void)name;
    if (x->depth-- > XML_MAX_DEPTH || x->out_of_memory || x->too_deep || !x->current) {
        return;
    }
    x->current = x->current->parent;
}

const char *drift__mts_attr(const xml_node *n, const char *key)
{
    for (char **a = n->attrs; a && a[0] && a[1]; a += 2) {
        if (strcmp(a[0], key) == 0) {
            return a[1];
        }
    }
    return NULL;
}

// --- SCENE BUILDING ---

drift_result drift__mts_fail(mitsuba_state *s, const xml_node *n, drift_result code,
                             const char *what, const char *detail)
{
    drift_log(s->ctx, DRIFT_LOG_ERROR, code, s->path, n ? n->line : 0, "%s%s%s", what,
              detail ? ": " : "", detail ? detail : "");
    return code;
}

void drift__mts_warn(mitsuba_state *s, const xml_node *n, const char *what)
{
    const char *type = drift__mts_attr(n, "type");
    const char *name = drift__mts_attr(n, "name");
    drift_log(s->ctx, DRIFT_LOG_WARNING, DRIFT_ERR_UNSUPPORTED, s->path, n->line,
              "<%s%s%s%s%s> %s; ignored", n->name, type ? " type=" : "", type ? type : "",
              name ? " name=" : "", name ? name : "", what);
}

// Up to n numbers separated by commas and/or spaces; returns how many were read.
int drift__mts_parse_numbers(const char *text, float *out, int n)
{
    int count = 0;
    const char *p = text;
    while (p && *p && count < n) {
        while (*p == ' ' || *p == ',' || *p == '\t' || *p == '\n' || *p == '\r') {
            ++p;
        }
        if (!*p) {
            break;
        }
        char *end = NULL;
        double v = strtod(p, &end);
        if (end == p || !isfinite(v) || fabs(v) > 3.0e38) {
            return -1;
        }
        out[count++] = (float)v;
        p = end;
    }
    return count;
}

// The child property `name` of element n (a <float>, <rgb>, <spectrum>, <point>, ...).
const xml_node *drift__mts_property(const xml_node *n, const char *name)
{
    for (const xml_node *c = n->first; c; c = c->next) {
        const char *cn = drift__mts_attr(c, "name");
        if (cn && strcmp(cn, name) == 0) {
            return c;
        }
    }
    return NULL;
}

drift_result drift__mts_read_float(mitsuba_state *s, const xml_node *n, const char *name,
                                   float fallback, float *out)
{
    const xml_node *p = drift__mts_property(n, name);
    *out = fallback;
    if (!p) {
        return DRIFT_OK;
    }
    const char *v = drift__mts_attr(p, "value");
    float f;
    if (!v || drift__mts_parse_numbers(v, &f, 1) != 1) {
        return drift__mts_fail(s, p, DRIFT_ERR_PARSE, "expected a number in value=", name);
    }
    *out = f;
    return DRIFT_OK;
}

// <rgb value="r, g, b"/> or <spectrum value="v"/> (one grey value) or <float value/>.
drift_result drift__mts_read_color(mitsuba_state *s, const xml_node *n, const char *name,
                                   drift_vec3 fallback, drift_vec3 *out, bool *found)
{
    const xml_node *p = drift__mts_property(n, name);
    *out = fallback;
    if (found) {
        *found = p != NULL;
    }
    if (!p || strcmp(p->name, "texture") == 0) {
        return DRIFT_OK;
    }
    const char *v = drift__mts_attr(p, "value");
    float c[3];
    int k = v ? drift__mts_parse_numbers(v, c, 3) : -1;
    if (k == 1) {
        c[1] = c[2] = c[0];
    } else if (k != 3) {
        return drift__mts_fail(s, p, DRIFT_ERR_PARSE,
                               "expected one or three numbers in value=", name);
    }
    if (c[0] < 0.0f || c[1] < 0.0f || c[2] < 0.0f) {
        return drift__mts_fail(s, p, DRIFT_ERR_INVALID_ARGUMENT, "negative colour", name);
    }
    *out = drift_vec3_make(c[0], c[1], c[2]);
    return DRIFT_OK;
}

static drift_result read_vec3_attrs(mitsuba_state *s, const xml_node *n, const char *key,
                                    drift_vec3 *out)
{
    const char *v = drift__mts_attr(n, key);
    float c[3];
    if (!v || drift__mts_parse_numbers(v, c, 3) != 3) {
        return drift__mts_fail(s, n, DRIFT_ERR_PARSE, "expected three numbers in attribute", key);
    }
    *out = drift_vec3_make(c[0], c[1], c[2]);
    return DRIFT_OK;
}

// <transform name="toWorld">: <matrix>, <lookat>, <translate>, <scale>, <rotate>, each
// applied after the ones before it.
static drift_result read_transform(mitsuba_state *s, const xml_node *n, drift__mat4 *out)
{
    *out = drift__mat4_identity();
    const xml_node *t = drift__mts_property(n, "toWorld");
    if (!t || strcmp(t->name, "transform") != 0) {
        return DRIFT_OK;
    }
    for (const xml_node *op = t->first; op; op = op->next) {
        drift__mat4 m = drift__mat4_identity();
        if (strcmp(op->name, "matrix") == 0) {
            const char *v = drift__mts_attr(op, "value");
            if (!v || drift__mts_parse_numbers(v, m.m, 16) != 16) {
                return drift__mts_fail(s, op, DRIFT_ERR_PARSE, "<matrix> needs 16 numbers", NULL);
            }
        } else if (strcmp(op->name, "lookat") == 0) {
            drift_vec3 origin = { 0 }, target = { 0 }, up = drift_vec3_make(0.0f, 1.0f, 0.0f);
            drift_result r;
            if ((r = read_vec3_attrs(s, op, "origin", &origin)) != DRIFT_OK ||
                (r = read_vec3_attrs(s, op, "target", &target)) != DRIFT_OK ||
                (drift__mts_attr(op, "up") &&
                 (r = read_vec3_attrs(s, op, "up", &up)) != DRIFT_OK)) {
                return r;
            }
            drift_vec3 dir = drift_vec3_normalize(drift_vec3_sub(target, origin));
            drift_vec3 left = drift_vec3_normalize(drift_vec3_cross(up, dir));
            drift_vec3 new_up = drift_vec3_cross(dir, left);
            m = (drift__mat4){ { left.x, new_up.x, dir.x, origin.x, left.y, new_up.y, dir.y,
                                 origin.y, left.z, new_up.z, dir.z, origin.z, 0, 0, 0, 1 } };
        } else if (strcmp(op->name, "translate") == 0 || strcmp(op->name, "scale") == 0) {
            bool scale = op->name[0] == 's';
            float v[3] = { scale ? 1.0f : 0.0f, scale ? 1.0f : 0.0f, scale ? 1.0f : 0.0f };
            const char *keys[3] = { "x", "y", "z" };
            for (int k = 0; k < 3; ++k) {
                const char *a = drift__mts_attr(op, keys[k]);
                if (a && drift__mts_parse_numbers(a, &v[k], 1) != 1) {
                    return drift__mts_fail(s, op, DRIFT_ERR_PARSE, "expected a number in", keys[k]);
                }
            }
            const char *uniform = drift__mts_attr(op, "value");
            if (scale && uniform) {
                if (drift__mts_parse_numbers(uniform, &v[0], 1) != 1) {
                    return drift__mts_fail(s, op, DRIFT_ERR_PARSE, "expected a number in", "value");
                }
                v[1] = v[2] = v[0];
            }
            if (scale) {
                m.m[0] = v[0];
                m.m[5] = v[1];
                m.m[10] = v[2];
            } else {
                m.m[3] = v[0];
                m.m[7] = v[1];
                m.m[11] = v[2];
            }
        } else if (strcmp(op->name, "rotate") == 0) {
            float a[4] = { 0, 0, 0, 0 };
            const char *keys[4] = { "x", "y", "z", "angle" };
            for (int k = 0; k < 4; ++k) {
                const char *v = drift__mts_attr(op, keys[k]);
                if (v && drift__mts_parse_numbers(v, &a[k], 1) != 1) {
                    return drift__mts_fail(s, op, DRIFT_ERR_PARSE, "expected a number in", keys[k]);
                }
            }
            drift_vec3 axis = drift_vec3_make(a[0], a[1], a[2]);
            if (drift_vec3_is_zero(axis)) {
                return drift__mts_fail(s, op, DRIFT_ERR_INVALID_ARGUMENT, "<rotate> needs an axis",
                                       NULL);
            }
            axis = drift_vec3_normalize(axis);
            float th = a[3] * DRIFT_PI / 180.0f, c = cosf(th), sn = sinf(th), t1 = 1.0f - c;
            float x = axis.x, y = axis.y, z = axis.z;
            m = (drift__mat4){ { t1 * x * x + c, t1 * x * y - sn * z, t1 * x * z + sn * y, 0,
                                 t1 * x * y + sn * z, t1 * y * y + c, t1 * y * z - sn * x, 0,
                                 t1 * x * z - sn * y, t1 * y * z + sn * x, t1 * z * z + c, 0, 0, 0,
                                 0, 1 } };
        } else {
            drift__mts_warn(s, op, "is not a supported transform");
            continue;
        }
        *out = drift__mat4_mul(&m, out);
    }
    return DRIFT_OK;
}

// Mitsuba's interior and exterior IORs (numbers or its names) as intIOR / extIOR.
// uvs: 2 a vertex (origin at the bottom left, as Mitsuba's and OBJ's), or NULL.
static drift_result add_triangles(mitsuba_state *s, const xml_node *n, const char *name,
                                  const float *local, const float *uvs, uint32_t vertex_count,
                                  const uint32_t *indices, uint32_t triangle_count,
                                  const drift__mat4 *world, uint32_t material)
{
    float *positions = drift_alloc(s->ctx, (size_t)vertex_count * 3 * sizeof(float));
    if (!positions) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t v = 0; v < vertex_count; ++v) {
        drift_vec3 p = drift__mat4_point(
            world, drift_vec3_make(local[3 * v], local[3 * v + 1], local[3 * v + 2]));
        positions[3 * v] = p.x;
        positions[3 * v + 1] = p.y;
        positions[3 * v + 2] = p.z;
    }
    drift_mesh_desc desc = { .name = name,
                             .positions = positions,
                             .uvs = uvs,
                             .indices = indices,
                             .vertex_count = vertex_count,
                             .triangle_count = triangle_count,
                             .material = material };
    drift_result r = drift_scene_add_mesh(s->scene, &desc, NULL);
    drift_free(s->ctx, positions);
    return r == DRIFT_OK ? DRIFT_OK : drift__mts_fail(s, n, r, "shape is not valid", name);
}

static drift_result read_shape(mitsuba_state *s, const xml_node *n)
{
    const char *type = drift__mts_attr(n, "type");
    if (!type) {
        return drift__mts_fail(s, n, DRIFT_ERR_PARSE, "<shape> without a type", NULL);
    }
    drift__mat4 world;
    drift_result r = read_transform(s, n, &world);
    if (r != DRIFT_OK) {
        return r;
    }
    // Its material: a <ref id>, a nested <bsdf>, or grey diffuse.
    uint32_t material = DRIFT_INVALID_INDEX;
    const xml_node *emitter = NULL;
    for (const xml_node *c = n->first; c && r == DRIFT_OK; c = c->next) {
        if (strcmp(c->name, "ref") == 0) {
            const char *id = drift__mts_attr(c, "id");
            bool found = false;
            for (uint32_t i = 0; id && i < s->bsdf_count && !found; ++i) {
                if (strcmp(s->bsdfs[i].id, id) == 0) {
                    material = s->bsdfs[i].material;
                    found = true;
                }
            }
            if (!found) {
                return drift__mts_fail(s, c, DRIFT_ERR_PARSE, "<ref> to an unknown bsdf id",
                                       id ? id : "(none)");
            }
        } else if (strcmp(c->name, "bsdf") == 0) {
            r = drift__mts_add_bsdf(s, c, &material);
        } else if (strcmp(c->name, "emitter") == 0) {
            emitter = c;
        }
    }
    if (r != DRIFT_OK) {
        return r;
    }
    drift_vec3 radiance = drift_vec3_splat(0.0f);
    if (emitter) {
        const char *et = drift__mts_attr(emitter, "type");
        if (!et || strcmp(et, "area") != 0) {
            drift__mts_warn(s, emitter, "inside a shape must be an area emitter");
            emitter = NULL;
        } else if ((r = drift__mts_read_color(s, emitter, "radiance", drift_vec3_splat(1.0f),
                                              &radiance, NULL)) != DRIFT_OK) {
            return r;
        }
    }
    if (material == DRIFT_INVALID_INDEX || emitter) {
        // A shape of its own colour, or an emitter: a material copy that carries the emission.
        drift_material m = material == DRIFT_INVALID_INDEX
                               ? drift_material_make(drift_vec3_splat(0.5f))
                               : s->scene->materials[material];
        snprintf(m.name, sizeof(m.name), "mitsuba#shape-line%d", n->line);
        m.emission = radiance;
        if ((r = drift_scene_add_material(s->scene, &m, &material)) != DRIFT_OK) {
            return drift__mts_fail(s, n, r, "material not valid", m.name);
        }
    }
    s->has_light = s->has_light || emitter;
    char name[DRIFT_NAME_MAX];
    snprintf(name, sizeof(name), "%s-line%d", type, n->line);
    s->shape_count++;
    if (strcmp(type, "obj") == 0 || strcmp(type, "ply") == 0) {
        const xml_node *file = drift__mts_property(n, "filename");
        const char *rel = file ? drift__mts_attr(file, "value") : NULL;
        char full[DRIFT__PATH_MAX];
        if (!rel || !drift__path_join(s->dir, rel, full, sizeof(full))) {
            return drift__mts_fail(s, n, DRIFT_ERR_PARSE, "<shape> needs a filename", type);
        }
        // faceNormals: Mitsuba shades the mesh flat, ignoring the file's normals.
        const xml_node *face = drift__mts_property(n, "faceNormals");
        const char *face_value = face ? drift__mts_attr(face, "value") : NULL;
        drift__import_params params = { .path = full,
                                        .where = s->path,
                                        .line = n->line,
                                        .transform = &world,
                                        .material_override = material,
                                        .textures = s->textures,
                                        .face_normals =
                                            face_value && strcmp(face_value, "true") == 0 };
        drift__import_info info;
        return drift__scene_import_mesh_file(s->scene, &params, &info);
    }
    if (strcmp(type, "rectangle") == 0) {
        static const float quad[] = { -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0 };
        static const float quad_uv[] = { 0, 0, 1, 0, 1, 1, 0, 1 }; // Mitsuba's rectangle's
        static const uint32_t tris[] = { 0, 1, 2, 0, 2, 3 };
        return add_triangles(s, n, name, quad, quad_uv, 4, tris, 2, &world, material);
    }
    if (strcmp(type, "cube") == 0) {
        float v[24];
        for (int i = 0; i < 8; ++i) {
            v[3 * i] = i & 1 ? 1.0f : -1.0f;
            v[3 * i + 1] = i & 2 ? 1.0f : -1.0f;
            v[3 * i + 2] = i & 4 ? 1.0f : -1.0f;
        }
        // Outward-facing (counter-clockwise seen from outside).
        static const uint32_t tris[] = { 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
                                         2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5 };
        return add_triangles(s, n, name, v, NULL, 8, tris, 12, &world, material);
    }
    if (strcmp(type, "sphere") == 0) {
        drift_vec3 center = drift_vec3_splat(0.0f);
        const xml_node *c = drift__mts_property(n, "center");
        if (c) {
            float xyz[3] = { 0, 0, 0 };
            const char *keys[3] = { "x", "y", "z" };
            for (int k = 0; k < 3; ++k) {
                const char *a = drift__mts_attr(c, keys[k]);
                if (a && drift__mts_parse_numbers(a, &xyz[k], 1) != 1) {
                    return drift__mts_fail(s, c, DRIFT_ERR_PARSE, "expected a number in", keys[k]);
                }
            }
            center = drift_vec3_make(xyz[0], xyz[1], xyz[2]);
        }
        float radius;
        if ((r = drift__mts_read_float(s, n, "radius", 1.0f, &radius)) != DRIFT_OK) {
            return r;
        }
        center = drift__mat4_point(&world, center);
        drift_vec3 scaled = drift__mat4_vector(&world, drift_vec3_make(radius, 0.0f, 0.0f));
        radius = drift_vec3_length(scaled);
        if (emitter) {
            drift_light light = {
                .type = DRIFT_LIGHT_SPHERE, .color = radiance, .position = center, .radius = radius
            };
            r = drift_scene_add_light(s->scene, &light, NULL);
            return r == DRIFT_OK ? DRIFT_OK
                                 : drift__mts_fail(s, n, r, "sphere emitter not valid", NULL);
        }

        // A plain sphere: 32 × 16 facets.
        enum {
            SEG = 32,
            RINGS = 16
        };

        float v[(SEG + 1) * (RINGS + 1) * 3];
        uint32_t tris[SEG * RINGS * 6];
        uint32_t t = 0;
        for (int j = 0; j <= RINGS; ++j) {
            float th = DRIFT_PI * (float)j / RINGS;
            for (int i = 0; i <= SEG; ++i) {
                float ph = 2.0f * DRIFT_PI * (float)i / SEG;
                float *p = &v[3 * (j * (SEG + 1) + i)];
                p[0] = center.x + radius * sinf(th) * cosf(ph);
                p[1] = center.y + radius * cosf(th);
                p[2] = center.z - radius * sinf(th) * sinf(ph);
            }
        }
        for (int j = 0; j < RINGS; ++j) {
            for (int i = 0; i < SEG; ++i) {
                uint32_t a = (uint32_t)(j * (SEG + 1) + i), b = a + SEG + 1;
                if (j > 0) {
                    tris[t++] = a, tris[t++] = b, tris[t++] = a + 1;
                }
                if (j < RINGS - 1) {
                    tris[t++] = a + 1, tris[t++] = b, tris[t++] = b + 1;
                }
            }
        }
        drift__mat4 identity = drift__mat4_identity();
        return add_triangles(s, n, name, v, NULL, (SEG + 1) * (RINGS + 1), tris, t / 3, &identity,
                             material);
    }
    return drift__mts_fail(s, n, DRIFT_ERR_UNSUPPORTED,
                           "unknown shape type (drift reads obj, ply, rectangle, cube, sphere)",
                           type);
}

static drift_result read_emitter(mitsuba_state *s, const xml_node *n)
{
    const char *type = drift__mts_attr(n, "type");
    drift__mat4 world;
    drift_result r = read_transform(s, n, &world);
    if (r != DRIFT_OK || !type) {
        return r != DRIFT_OK
                   ? r
                   : drift__mts_fail(s, n, DRIFT_ERR_PARSE, "<emitter> without a type", NULL);
    }
    drift_light light = { 0 };
    if (strcmp(type, "constant") == 0) {
        s->has_light = true;
        return drift__mts_read_color(s, n, "radiance", drift_vec3_splat(1.0f),
                                     &s->scene->environment.color, NULL);
    }
    if (strcmp(type, "envmap") == 0) {
        const xml_node *file = drift__mts_property(n, "filename");
        const char *rel = file ? drift__mts_attr(file, "value") : NULL;
        char full[DRIFT__PATH_MAX];
        float scale;
        uint32_t index;
        if ((r = drift__mts_read_float(s, n, "scale", 1.0f, &scale)) != DRIFT_OK) {
            return r;
        }
        if (!rel || !drift__path_join(s->dir, rel, full, sizeof(full))) {
            return drift__mts_fail(s, n, DRIFT_ERR_PARSE, "<emitter type=envmap> needs a filename",
                                   NULL);
        }
        if ((r = drift__texture_cache_get(s->scene, s->textures, full, s->path, n->line, &index)) !=
            DRIFT_OK) {
            return r;
        }
        s->scene->environment = (drift_environment){ drift_vec3_splat(scale), index };
        s->has_light = true;
        drift__mts_warn(s, n, "orientation (toWorld) is not applied to the map");
        return DRIFT_OK;
    }
    if (strcmp(type, "point") == 0) {
        light.type = DRIFT_LIGHT_POINT;
        drift_vec3 pos = drift_vec3_splat(0.0f);
        const xml_node *p = drift__mts_property(n, "position");
        if (p) {
            float xyz[3] = { 0, 0, 0 };
            const char *keys[3] = { "x", "y", "z" };
            for (int k = 0; k < 3; ++k) {
                const char *a = drift__mts_attr(p, keys[k]);
                if (a && drift__mts_parse_numbers(a, &xyz[k], 1) != 1) {
                    return drift__mts_fail(s, p, DRIFT_ERR_PARSE, "expected a number in", keys[k]);
                }
            }
            pos = drift_vec3_make(xyz[0], xyz[1], xyz[2]);
        }
        light.position = drift__mat4_point(&world, pos);
        r = drift__mts_read_color(s, n, "intensity", drift_vec3_splat(1.0f), &light.color, NULL);
    } else if (strcmp(type, "spot") == 0) {
        float cutoff, beam;
        light.type = DRIFT_LIGHT_SPOT;
        light.position = drift__mat4_point(&world, drift_vec3_splat(0.0f));
        light.direction =
            drift_vec3_normalize(drift__mat4_vector(&world, drift_vec3_make(0.0f, 0.0f, 1.0f)));
        if ((r = drift__mts_read_color(s, n, "intensity", drift_vec3_splat(1.0f), &light.color,
                                       NULL)) == DRIFT_OK &&
            (r = drift__mts_read_float(s, n, "cutoffAngle", 20.0f, &cutoff)) == DRIFT_OK &&
            (r = drift__mts_read_float(s, n, "beamWidth", cutoff * 0.75f, &beam)) == DRIFT_OK) {
            light.spot_outer = drift_clampf(cutoff, 0.0f, 180.0f) * DRIFT_PI / 180.0f;
            light.spot_inner = drift_clampf(beam * DRIFT_PI / 180.0f, 0.0f, light.spot_outer);
        }
    } else if (strcmp(type, "directional") == 0) {
        light.type = DRIFT_LIGHT_DIRECTIONAL;
        light.direction =
            drift_vec3_normalize(drift__mat4_vector(&world, drift_vec3_make(0.0f, 0.0f, 1.0f)));
        const xml_node *d = drift__mts_property(n, "direction");
        if (d) {
            float xyz[3] = { 0, 0, 1 };
            const char *keys[3] = { "x", "y", "z" };
            for (int k = 0; k < 3; ++k) {
                const char *a = drift__mts_attr(d, keys[k]);
                if (a && drift__mts_parse_numbers(a, &xyz[k], 1) != 1) {
                    return drift__mts_fail(s, d, DRIFT_ERR_PARSE, "expected a number in", keys[k]);
                }
            }
            light.direction = drift_vec3_normalize(drift_vec3_make(xyz[0], xyz[1], xyz[2]));
        }
        r = drift__mts_read_color(s, n, "irradiance", drift_vec3_splat(1.0f), &light.color, NULL);
    } else {
        drift__mts_warn(s, n, "is not a supported emitter (sunsky, sky, sun: use an envmap)");
        return DRIFT_OK;
    }
    if (r == DRIFT_OK) {
        r = drift_scene_add_light(s->scene, &light, NULL);
        if (r != DRIFT_OK) {
            return drift__mts_fail(s, n, r, "emitter not valid", type);
        }
        s->has_light = true;
    }
    return r;
}

static drift_result read_sensor(mitsuba_state *s, const xml_node *n)
{
    const char *type = drift__mts_attr(n, "type");
    if (!type || (strcmp(type, "perspective") != 0 && strcmp(type, "thinlens") != 0)) {
        drift__mts_warn(s, n, "is not a supported sensor (perspective, thinlens)");
        return DRIFT_OK;
    }
    drift__mat4 world;
    drift_result r = read_transform(s, n, &world);
    float fov, width = 768.0f, height = 576.0f;
    if (r != DRIFT_OK || (r = drift__mts_read_float(s, n, "fov", 45.0f, &fov)) != DRIFT_OK) {
        return r;
    }
    for (const xml_node *c = n->first; c; c = c->next) {
        if (strcmp(c->name, "film") == 0 &&
            ((r = drift__mts_read_float(s, c, "width", width, &width)) != DRIFT_OK ||
             (r = drift__mts_read_float(s, c, "height", height, &height)) != DRIFT_OK)) {
            return r;
        }
    }
    if (!(width >= 1.0f && width <= 32768.0f && height >= 1.0f && height <= 32768.0f &&
          fov > 0.0f && fov < 180.0f)) {
        return drift__mts_fail(s, n, DRIFT_ERR_INVALID_ARGUMENT,
                               "sensor fov or film size out of range", NULL);
    }
    // fovAxis: x (the default), y, smaller or larger; drift keeps the vertical angle.
    const xml_node *axis_node = drift__mts_property(n, "fovAxis");
    const char *axis = axis_node ? drift__mts_attr(axis_node, "value") : "x";
    axis = axis ? axis : "x";
    bool horizontal = strcmp(axis, "x") == 0 || (strcmp(axis, "smaller") == 0 && width <= height) ||
                      (strcmp(axis, "larger") == 0 && width >= height);
    float half = 0.5f * fov * DRIFT_PI / 180.0f;
    float fov_y = horizontal ? 2.0f * atanf(tanf(half) * height / width) : 2.0f * half;
    drift_vec3 eye = drift__mat4_point(&world, drift_vec3_splat(0.0f));
    drift_vec3 forward = drift__mat4_vector(&world, drift_vec3_make(0.0f, 0.0f, 1.0f));
    drift_vec3 up = drift__mat4_vector(&world, drift_vec3_make(0.0f, 1.0f, 0.0f));
    s->scene->camera = drift_camera_look_at(eye, drift_vec3_add(eye, forward), up, fov_y,
                                            (int32_t)width, (int32_t)height);
    s->has_camera = true;
    return DRIFT_OK;
}

static drift_result build_scene(mitsuba_state *s, const xml_node *root)
{
    if (strcmp(root->name, "scene") != 0) {
        return drift__mts_fail(s, root, DRIFT_ERR_PARSE, "the root element must be <scene>",
                               root->name);
    }
    drift_result r = DRIFT_OK;
    for (const xml_node *c = root->first; c && r == DRIFT_OK; c = c->next) {
        if (strcmp(c->name, "bsdf") == 0) {
            uint32_t m;
            r = drift__mts_add_bsdf(s, c, &m);
        } else if (strcmp(c->name, "shape") == 0) {
            r = read_shape(s, c);
        } else if (strcmp(c->name, "emitter") == 0) {
            r = read_emitter(s, c);
        } else if (strcmp(c->name, "sensor") == 0) {
            r = read_sensor(s, c);
        } else if (strcmp(c->name, "background") == 0) {
            // Mitsuba 0.4's constant background.
            r = drift__mts_read_color(s, c, "radiance", drift_vec3_splat(0.0f),
                                      &s->scene->environment.color, NULL);
            s->has_light = true;
        } else if (strcmp(c->name, "integrator") == 0 || strcmp(c->name, "default") == 0) {
            // drift's own integrator and options; not a warning.
        } else {
            drift__mts_warn(s, c, "is not supported");
        }
    }
    if (r == DRIFT_OK && s->shape_count == 0) {
        r = drift__mts_fail(s, root, DRIFT_ERR_PARSE, "the scene has no shapes", NULL);
    }
    return r;
}

drift_result drift__scene_load_mitsuba(drift_context *ctx, const char *path,
                                       drift_scene_input_fn on_input, void *user,
                                       drift_scene **out_scene)
{
    *out_scene = NULL;
    char *text = NULL;
    size_t size = 0;
    drift_result r = drift__read_file(ctx, path, false, path, 0, &text, &size);
    if (r != DRIFT_OK) {
        return r;
    }
    if (on_input) {
        on_input(path, user);
    }
    xml_reader x = { .ctx = ctx };
    XML_Parser parser = XML_ParserCreate(NULL);
    if (!parser) {
        drift_free(ctx, text);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    XML_SetUserData(parser, &x);
    XML_SetElementHandler(parser, on_start, on_end);
    x.parser = parser;
    bool ok = size <= (size_t)0x7fffffff && XML_Parse(parser, text, (int)size, 1) == XML_STATUS_OK;
    drift_free(ctx, text);
    if (!ok || x.too_deep || x.out_of_memory || !x.root) {
        drift_result code = x.out_of_memory ? DRIFT_ERR_OUT_OF_MEMORY : DRIFT_ERR_PARSE;
        drift_log(ctx, DRIFT_LOG_ERROR, code, path, (int)XML_GetCurrentLineNumber(parser),
                  "malformed Mitsuba XML: %s",
                  x.too_deep ? "elements nested too deep"
                  : !ok      ? XML_ErrorString(XML_GetErrorCode(parser))
                             : "no root element");
        XML_ParserFree(parser);
        free_node(ctx, x.root);
        return code;
    }
    XML_ParserFree(parser);
    if ((r = drift__mitsuba3_normalize(ctx, path, x.root)) != DRIFT_OK) {
        free_node(ctx, x.root);
        return r;
    }

    drift_scene *scene = NULL;
    if ((r = drift_scene_create(ctx, &scene)) != DRIFT_OK) {
        free_node(ctx, x.root);
        return r;
    }
    drift__texture_cache textures = { .on_input = on_input, .user = user };
    mitsuba_state s = { .ctx = ctx, .scene = scene, .path = path, .textures = &textures };
    const char *slash = strrchr(path, '/');
    snprintf(s.dir, sizeof(s.dir), "%.*s", slash ? (int)(slash - path) : 1, slash ? path : ".");
    r = build_scene(&s, x.root);
    if (r == DRIFT_OK && !s.has_camera) {
        scene->camera = drift__framing_camera(drift__scene_mesh_bounds(scene));
    }
    if (r == DRIFT_OK) {
        r = drift_scene_commit(scene);
        if (r != DRIFT_OK) {
            drift_log(ctx, DRIFT_LOG_ERROR, r, path, 0, "the scene is not valid (see above)");
        }
    }
    drift__texture_cache_clear(ctx, &textures);
    drift_free(ctx, s.bsdfs);
    free_node(ctx, x.root);
    if (r != DRIFT_OK) {
        drift_scene_destroy(scene);
        return r;
    }
    *out_scene = scene;
    return DRIFT_OK;
}
