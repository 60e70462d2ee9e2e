// What assimp 5.2 does not tell about an OBJ file and its MTL libraries, read from their text
// (docs/scene-format.md, "OBJ and MTL"):
//
// - a file cut short (a last record no newline ends) is an error naming the line;
// - an `mtllib` that does not exist, and a texture an MTL names that does not, are warnings
//   naming the file and line that named them (assimp says nothing);
// - smoothing groups: an object (`o`/`g`) with `s 1` (any group but 0/off) and no normals is
//   shaded smooth, as Blender's importer shows it (assimp keeps it faceted);
// - per material: whether `Kd` is given (Blender's exporter leaves it out beside `map_Kd`:
//   the texture alone is the colour, where assimp would multiply it by its default 0.6), the
//   `map_Kd` file name with surrounding whitespace removed (trailing tabs/spaces made assimp
//   look for a file that does not exist), `illum`, the dissolve `d` (or `Tr`) and `map_d`
//   (the material's opacity), and warnings for what drift's material cannot hold (map_Ks,
//   map_Ns, map_Bump/bump, norm, illum ≥ 3).
#include "scene_io_internal.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

typedef struct obj_object {
    char name[DRIFT_NAME_MAX];
    bool smooth;
} obj_object;

struct drift__obj {
    obj_object *objects; // objects[0]: statements before any o/g
    size_t object_count;
    drift__obj_material *materials;
    size_t material_count;
    char mtl_paths[8][DRIFT__PATH_MAX]; // the libraries read (materials point into these)
    size_t mtl_count;
};

// The OBJ and MTL statements drift reads itself, beside assimp's reading, and what it makes of
// them (docs/reference/scene-formats.md prints this table; docs/scene-format.md explains).
const drift__format_row drift__obj_statements[] = {
    { "mtllib", "a missing library is a warning naming the OBJ's file and line" },
    { "o, g, s", "a smoothing group on (s 1) without vn: area-weighted smooth normals" },
    { "newmtl", "starts a material; a texture statement before it is an error" },
    { "Kd", "diffuse colour (multiplies map_Kd)" },
    { "map_Kd", "diffuse texture, options skipped; alone (no Kd): the colour" },
    { "Ks", "Blender MTL: Principled specular mean(Ks), F0 = 0.08 · it" },
    { "Ns", "Blender MTL: roughness 1 − √(Ns / 1000)" },
    { "illum", "0, 1: no highlight without Ks; ≥ 3: drawn as 2, with a warning" },
    { "Ke", "emission (radiance)" },
    { "d, Tr, map_d", "opacity d (1 − Tr) times map_d's alpha (its grey without one): "
                      "stochastic transparency, as Cycles renders Blender's import" },
    { "map_Ks, map_Ns, map_Bump, bump, norm, disp, map_Ke, refl", "a warning each" },
    { "Ni, Ka", "ignored" },
};
const size_t drift__obj_statement_count =
    sizeof drift__obj_statements / sizeof *drift__obj_statements;

// The next line of text[*at .. size) without its end-of-line and surrounding whitespace,
// into out (cut at out_size - 1); false at the end.
static bool next_line(const char *text, size_t size, size_t *at, char *out, size_t out_size)
{
    if (*at >= size) {
        return false;
    }
    const char *start = text + *at;
    const char *nl = memchr(start, '\n', size - *at);
    size_t n = nl ? (size_t)(nl - start) : size - *at;
    *at += n + (nl ? 1 : 0);
    while (n > 0 && isspace((unsigned char)start[n - 1])) {
        --n;
    }
    size_t skip = 0;
    while (skip < n && isspace((unsigned char)start[skip])) {
        ++skip;
    }
    n -= skip;
    n = n < out_size - 1 ? n : out_size - 1;
    memcpy(out, start + skip, n);
    out[n] = '\0';
    return true;
}

// Whether `line` is statement `key` (followed by whitespace or its end); *rest: its argument.
static bool statement(const char *line, const char *key, const char **rest)
{
    size_t n = strlen(key);
    if (strncmp(line, key, n) != 0 || (line[n] != '\0' && !isspace((unsigned char)line[n]))) {
        return false;
    }
    const char *r = line + n;
    while (isspace((unsigned char)*r)) {
        ++r;
    }
    *rest = r;
    return true;
}

// The file name of a texture statement's argument: the options (-o u v w, -s u v w, -bm b,
// -clamp on, ...) skipped, the rest as it is (names may hold spaces).
static const char *texture_file(const char *arg)
{
    const char *p = arg;
    while (*p == '-') {
        while (*p && !isspace((unsigned char)*p)) { // the option
            ++p;
        }
        for (;;) { // its values: numbers and on/off
            while (isspace((unsigned char)*p)) {
                ++p;
            }
            char *end = NULL;
            strtod(p, &end);
            bool number = end != p && (*end == '\0' || isspace((unsigned char)*end));
            bool toggle =
                (strncmp(p, "on", 2) == 0 && (p[2] == '\0' || isspace((unsigned char)p[2]))) ||
                (strncmp(p, "off", 3) == 0 && (p[3] == '\0' || isspace((unsigned char)p[3])));
            if (!number && !toggle) {
                break;
            }
            p = number ? end : p + (p[1] == 'n' ? 2 : 3);
        }
    }
    return p;
}

static drift__obj_material *add_material(drift_context *ctx, drift__obj *o, const char *name,
                                         const char *mtl_path)
{
    drift__obj_material *grown = drift_realloc(ctx, o->materials, o->material_count * sizeof *grown,
                                               (o->material_count + 1) * sizeof *grown);
    if (!grown) {
        return NULL;
    }
    o->materials = grown;
    drift__obj_material *m = &o->materials[o->material_count++];
    *m = (drift__obj_material){ .illum = 2, .dissolve = 1.0f, .mtl_path = mtl_path };
    snprintf(m->name, sizeof m->name, "%s", name);
    return m;
}

// OBJ and MTL files are text: a NUL byte is refused with its line, since assimp's MTL reader
// writes through a null material on one (fuzz_scene_mtl).
static drift_result check_text(drift_context *ctx, const char *path, const char *text, size_t size)
{
    const char *nul = memchr(text, '\0', size);
    if (!nul) {
        return DRIFT_OK;
    }
    int line = 1;
    for (const char *c = text; c < nul; ++c) {
        line += *c == '\n';
    }
    drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, path, line,
              "a NUL byte: an OBJ or MTL file is text");
    return DRIFT_ERR_PARSE;
}

// Reads one MTL library: its materials, and a warning for each statement drift drops.
static drift_result read_mtl(drift_context *ctx, drift__obj *o, const char *path)
{
    char *text = NULL;
    size_t size = 0;
    drift_result r = drift__read_file(ctx, path, false, path, 0, &text, &size);
    if (r != DRIFT_OK) {
        return r;
    }
    if ((r = check_text(ctx, path, text, size)) != DRIFT_OK) {
        drift_free(ctx, text);
        return r;
    }

    static const struct {
        const char *key, *what;
    } dropped[] = {
        { "map_Ks", "specular colour texture" },
        { "map_Ns", "specular exponent texture" },
        { "map_Bump", "bump map" },
        { "bump", "bump map" },
        { "map_bump", "bump map" },
        { "norm", "normal map" },
        { "disp", "displacement map" },
        { "map_Ke", "emission texture" },
        { "refl", "reflection map" },
    };

    // Blender 2.8 and later head their MTLs "# Blender 3.4.1 MTL File" ("# Blender v2.93.0
    // MTL File" before 3.2): their materials are Principled BSDFs, read back by Blender's rule
    // (drift__obj_blender_material). Older ones ("# Blender MTL File", 2.7x) and other
    // writers' keep the plain MTL reading.
    bool blender = size > 11 && strncmp(text, "# Blender ", 10) == 0 &&
                   (isdigit((unsigned char)text[10]) ||
                    (text[10] == 'v' && isdigit((unsigned char)text[11]) && text[11] >= '2' &&
                     !(text[11] == '2' && size > 13 && text[13] < '8')));
    drift__obj_material *m = NULL;
    char line[DRIFT__PATH_MAX];
    size_t at = 0;
    for (int number = 1; next_line(text, size, &at, line, sizeof line); ++number) {
        const char *arg = NULL;
        // A texture statement names no material before the first newmtl, and assimp's MTL
        // reader writes its texture through a null material there (fuzz_scene_mtl).
        const char *head = line;
        while (*head == ' ' || *head == '\t') {
            ++head;
        }
        // A statement starts with a letter, a comment with '#': assimp's MTL reader misreads
        // the lines after one that starts with another byte (0xce, 0x01; fuzz_scene_mtl).
        if (*head && *head != '\r' && *head != '#' && !isalpha((unsigned char)*head)) {
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, path, number,
                      "not an MTL statement (a statement starts with a letter)");
            drift_free(ctx, text);
            return DRIFT_ERR_PARSE;
        }
        if (!m && (strncmp(head, "map_", 4) == 0 || statement(head, "bump", &arg) ||
                   statement(head, "disp", &arg) || statement(head, "decal", &arg) ||
                   statement(head, "refl", &arg) || statement(head, "norm", &arg))) {
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, path, number,
                      "a texture statement before any newmtl");
            drift_free(ctx, text);
            return DRIFT_ERR_PARSE;
        }
        if (statement(line, "newmtl", &arg)) {
            m = add_material(ctx, o, arg, path);
            if (!m) {
                r = DRIFT_ERR_OUT_OF_MEMORY;
                break;
            }
            m->blender = blender;
            continue;
        }
        if (!m) {
            continue;
        }
        float a = 0.0f, b = 0.0f, c = 0.0f;
        if (statement(line, "Kd", &arg)) {
            m->has_kd = true;
        } else if (statement(line, "Ks", &arg)) {
            int n = sscanf(arg, "%f %f %f", &a, &b, &c);
            m->has_ks = n >= 1;
            m->ks = n >= 3 ? (a + b + c) / 3.0f : a; // Blender: the mean, one value grey
        } else if (statement(line, "Ns", &arg)) {
            m->has_ns = sscanf(arg, "%f", &m->ns) == 1 && isfinite(m->ns);
        } else if (statement(line, "map_Kd", &arg)) {
            snprintf(m->map_kd, sizeof m->map_kd, "%s", texture_file(arg));
            m->map_kd_line = number;
        } else if (statement(line, "illum", &arg)) {
            m->illum = atoi(arg);
            if (m->illum >= 3) {
                drift_log(ctx, DRIFT_LOG_WARNING, DRIFT_ERR_UNSUPPORTED, path, number,
                          "material '%s': illum %d (reflection, refraction) is drawn as illum 2 "
                          "(a glossy highlight)",
                          m->name, m->illum);
            }
        } else if (statement(line, "d", &arg) || statement(line, "Tr", &arg)) {
            bool tr = line[0] == 'T';
            double v = strtod(arg, NULL), d = tr ? 1.0 - v : v;
            if (!(d >= 0.0 && d <= 1.0)) {
                drift_log(ctx, DRIFT_LOG_WARNING, DRIFT_ERR_INVALID_ARGUMENT, path, number,
                          "material '%s': %s %s is not in [0, 1]; %s", m->name, tr ? "Tr" : "d",
                          arg, d < 0.0 ? "transparent" : "opaque");
                d = d < 0.0 ? 0.0 : 1.0;
            }
            m->dissolve = (float)d;
        } else if (statement(line, "map_d", &arg)) {
            snprintf(m->map_d, sizeof m->map_d, "%s", texture_file(arg));
            m->map_d_line = number;
        } else {
            for (size_t k = 0; k < sizeof dropped / sizeof dropped[0]; ++k) {
                if (statement(line, dropped[k].key, &arg)) {
                    drift_log(ctx, DRIFT_LOG_WARNING, DRIFT_ERR_UNSUPPORTED, path, number,
                              "material '%s': %s '%s' ignored (drift's material has no %s)",
                              m->name, dropped[k].key, texture_file(arg), dropped[k].what);
                }
            }
        }
    }
    drift_free(ctx, text);
    return r;
}

static obj_object *add_object(drift_context *ctx, drift__obj *o, const char *name)
{
    for (size_t i = 1; i < o->object_count; ++i) {
        if (strcmp(o->objects[i].name, name) == 0) {
            return &o->objects[i];
        }
    }
    obj_object *grown = drift_realloc(ctx, o->objects, o->object_count * sizeof *grown,
                                      (o->object_count + 1) * sizeof *grown);
    if (!grown) {
        return NULL;
    }
    o->objects = grown;
    obj_object *ob = &o->objects[o->object_count++];
    *ob = (obj_object){ 0 };
    snprintf(ob->name, sizeof ob->name, "%s", name);
    return ob;
}

// The `mtllib` statement's libraries (one or more names), each read or warned about.
static drift_result read_mtllib(drift_context *ctx, drift__obj *o, const char *obj_path,
                                const char *dir, const char *arg, int number)
{
    char names[DRIFT__PATH_MAX];
    snprintf(names, sizeof names, "%s", arg);
    // Blender writes one name, which may hold spaces; try the whole argument first.
    char full[DRIFT__PATH_MAX];
    if (drift__path_join(dir, names, full, sizeof full) && access(full, R_OK) == 0) {
        if (o->mtl_count < sizeof o->mtl_paths / sizeof o->mtl_paths[0]) {
            snprintf(o->mtl_paths[o->mtl_count], DRIFT__PATH_MAX, "%s", full);
            return read_mtl(ctx, o, o->mtl_paths[o->mtl_count++]);
        }
        return DRIFT_OK;
    }
    drift_log(ctx, DRIFT_LOG_WARNING, DRIFT_ERR_IO, obj_path, number,
              "material library '%s' not found (looked for %s): its materials are grey", names,
              full);
    return DRIFT_OK;
}

// An OBJ cut short: assimp reads what is there without a word. A last record (v, vt, vn, f,
// l, p) that no newline ends is taken as the file cut mid-line.
static drift_result check_tail(drift_context *ctx, const char *path, const char *text, size_t size)
{
    if (size == 0 || text[size - 1] == '\n') {
        return DRIFT_OK;
    }
    size_t start = size;
    int line = 1;
    for (size_t i = 0; i < size; ++i) {
        if (text[i] == '\n') {
            ++line;
            start = i + 1;
        }
    }
    start = start == size ? 0 : start;
    static const char *const records[] = { "v ", "vt ", "vn ", "f ", "l ", "p ", "v\t", "f\t" };
    for (size_t i = 0; i < sizeof records / sizeof records[0]; ++i) {
        size_t n = strlen(records[i]);
        if (size - start >= n && strncmp(text + start, records[i], n) == 0) {
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, path, line,
                      "the file ends in the middle of this line (cut short?); no newline ends "
                      "its last record");
            return DRIFT_ERR_PARSE;
        }
    }
    return DRIFT_OK;
}

drift_result drift__obj_open(drift_context *ctx, const char *path, const char *text, size_t size,
                             drift__obj **out)
{
    *out = NULL;
    drift_result r = check_text(ctx, path, text, size);
    r = r ? r : check_tail(ctx, path, text, size);
    drift__obj *o = r == DRIFT_OK ? drift_alloc(ctx, sizeof *o) : NULL;
    if (r != DRIFT_OK || !o) {
        return r != DRIFT_OK ? r : DRIFT_ERR_OUT_OF_MEMORY;
    }
    *o = (drift__obj){ 0 };
    char dir[DRIFT__PATH_MAX] = ".";
    const char *slash = strrchr(path, '/');
    if (slash) {
        snprintf(dir, sizeof dir, "%.*s", slash == path ? 1 : (int)(slash - path), path);
    }
    obj_object *current = add_object(ctx, o, "");
    char line[DRIFT__PATH_MAX];
    size_t at = 0;
    for (int number = 1; current && r == DRIFT_OK && next_line(text, size, &at, line, sizeof line);
         ++number) {
        const char *arg = NULL;
        if (line[0] == 'v' || line[0] == 'f' || line[0] == '#') {
            continue; // the bulk of the file
        }
        size_t index = (size_t)(current - o->objects);
        if (statement(line, "o", &arg) || statement(line, "g", &arg)) {
            current = add_object(ctx, o, arg);
        } else if (statement(line, "s", &arg)) {
            bool on = strcmp(arg, "0") != 0 && strcmp(arg, "off") != 0 && arg[0] != '\0';
            o->objects[index].smooth = o->objects[index].smooth || on;
        } else if (statement(line, "mtllib", &arg)) {
            r = read_mtllib(ctx, o, path, dir, arg, number);
        }
    }
    if (!current && r == DRIFT_OK) {
        r = DRIFT_ERR_OUT_OF_MEMORY;
    }
    if (r != DRIFT_OK) {
        drift__obj_close(ctx, o);
        return r;
    }
    *out = o;
    return DRIFT_OK;
}

void drift__obj_close(drift_context *ctx, drift__obj *o)
{
    if (o) {
        drift_free(ctx, o->objects);
        drift_free(ctx, o->materials);
        drift_free(ctx, o);
    }
}

bool drift__obj_smooth(const drift__obj *o, const char *object)
{
    if (!o) {
        return false;
    }
    for (size_t i = 1; i < o->object_count; ++i) {
        if (strcmp(o->objects[i].name, object) == 0) {
            return o->objects[i].smooth;
        }
    }
    return o->object_count > 0 && o->objects[0].smooth;
}

const drift__obj_material *drift__obj_get_material(const drift__obj *o, const char *name)
{
    for (size_t i = 0; o && i < o->material_count; ++i) {
        if (strcmp(o->materials[i].name, name) == 0) {
            return &o->materials[i];
        }
    }
    return NULL;
}

// Smooth vertex normals: each vertex gets the area-weighted normals of the faces around its
// position (vertices at one position, split by their UVs, share one normal).
drift_result drift__smooth_normals(drift_context *ctx, const float *positions, size_t vertex_count,
                                   const uint32_t *indices, size_t triangle_count,
                                   float **out_normals)
{
    *out_normals = NULL;
    size_t buckets = 1;
    while (buckets < 2 * vertex_count + 1) {
        buckets *= 2;
    }
    float *normals = drift_alloc(ctx, vertex_count * 3 * sizeof(float));
    float *sums = drift_alloc(ctx, vertex_count * 3 * sizeof(float));
    uint32_t *slot = drift_alloc(ctx, buckets * sizeof(uint32_t));      // bucket -> a vertex
    uint32_t *weld = drift_alloc(ctx, vertex_count * sizeof(uint32_t)); // vertex -> first at p
    if (!normals || !sums || !slot || !weld) {
        drift_free(ctx, normals);
        drift_free(ctx, sums);
        drift_free(ctx, slot);
        drift_free(ctx, weld);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    memset(slot, 0xff, buckets * sizeof(uint32_t));
    for (size_t v = 0; v < vertex_count; ++v) {
        const float *p = positions + 3 * v;
        uint32_t bits[3];
        memcpy(bits, p, sizeof bits);
        size_t h = ((size_t)bits[0] * 73856093u ^ (size_t)bits[1] * 19349663u ^
                    (size_t)bits[2] * 83492791u) &
                   (buckets - 1);
        while (slot[h] != UINT32_MAX && memcmp(positions + 3 * (size_t)slot[h], p, 12) != 0) {
            h = (h + 1) & (buckets - 1);
        }
        if (slot[h] == UINT32_MAX) {
            slot[h] = (uint32_t)v;
        }
        weld[v] = slot[h];
    }
    memset(sums, 0, vertex_count * 3 * sizeof(float));
    for (size_t t = 0; t < triangle_count; ++t) {
        const float *a = positions + 3 * (size_t)indices[3 * t];
        const float *b = positions + 3 * (size_t)indices[3 * t + 1];
        const float *c = positions + 3 * (size_t)indices[3 * t + 2];
        drift_vec3 n = drift_vec3_cross(
            drift_vec3_make(b[0] - a[0], b[1] - a[1], b[2] - a[2]),
            drift_vec3_make(c[0] - a[0], c[1] - a[1], c[2] - a[2])); // length: twice the area
        for (int k = 0; k < 3; ++k) {
            float *w = sums + 3 * (size_t)weld[indices[3 * t + (size_t)k]];
            w[0] += n.x;
            w[1] += n.y;
            w[2] += n.z;
        }
    }
    for (size_t v = 0; v < vertex_count; ++v) {
        const float *w = sums + 3 * (size_t)weld[v];
        drift_vec3 n = drift_vec3_make(w[0], w[1], w[2]);
        float len = drift_vec3_length(n);
        n = len > 0.0f ? drift_vec3_scale(n, 1.0f / len) : drift_vec3_make(0.0f, 0.0f, 1.0f);
        normals[3 * v] = n.x;
        normals[3 * v + 1] = n.y;
        normals[3 * v + 2] = n.z;
    }
    drift_free(ctx, sums);
    drift_free(ctx, slot);
    drift_free(ctx, weld);
    *out_normals = normals;
    return DRIFT_OK;
}

// Glossy exponent of drift's normalized Phong lobe for a roughness: the rule of scene_gltf.c
// (α = roughness², Walter et al.'s n = 2/α² − 2, a quarter of it about the mirror direction).
static float exponent_of_roughness(float roughness)
{
    float alpha = drift_clampf(roughness, 0.0f, 1.0f);
    alpha *= alpha;
    if (alpha < 1e-4f) {
        return 10000.0f;
    }
    return drift_clampf(0.25f * (2.0f / (alpha * alpha) - 2.0f), 1.0f, 10000.0f);
}

void drift__obj_blender_material(const drift__obj_material *om, drift_material *m)
{
    bool highlight = om->illum >= 2;
    float roughness = om->has_ns  ? 1.0f - sqrtf(drift_clampf(om->ns, 0.0f, 1000.0f) / 1000.0f)
                      : highlight ? 0.0f
                                  : 1.0f;
    float specular = om->has_ks ? drift_clampf(om->ks, 0.0f, 1.0f) : highlight ? 1.0f : 0.0f;
    float f0 = 0.08f * specular; // Principled BSDF: F0 = 0.08 · Specular
    m->diffuse_model = DRIFT_DIFFUSE_BURLEY;
    m->diffuse_roughness = roughness;
    m->specular = drift_vec3_splat(f0);
    m->exponent = f0 > 0.0f ? exponent_of_roughness(roughness) : 0.0f;
    m->diffuse = drift_vec3_make(fminf(m->diffuse.x, 1.0f - f0), fminf(m->diffuse.y, 1.0f - f0),
                                 fminf(m->diffuse.z, 1.0f - f0));
}
