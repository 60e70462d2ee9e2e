// Private to the Mitsuba reader: scene_mitsuba.c (the XML, shapes, emitters, sensor) and
// scene_mitsuba_bsdf.c (the BSDFs onto drift's materials) share the scene being built and the
// property readers.
#ifndef DRIFT_SCENE_MITSUBA_INTERNAL_H
#define DRIFT_SCENE_MITSUBA_INTERNAL_H

#include "scene_io_internal.h"
#include "scene_mitsuba_xml.h"

typedef struct named_bsdf {
    const char *id;
    uint32_t material;
} named_bsdf;

typedef struct mitsuba_state {
    drift_context *ctx;
    drift_scene *scene;
    const char *path;
    char dir[DRIFT__PATH_MAX];
    drift__texture_cache *textures;
    named_bsdf *bsdfs;
    uint32_t bsdf_count, bsdf_capacity;
    uint32_t shape_count;
    bool has_camera, has_light;
} mitsuba_state;

// The value of attribute `key`, or NULL.
const char *drift__mts_attr(const xml_node *n, const char *key);
// Logs an error against the element's line; returns code.
drift_result drift__mts_fail(mitsuba_state *s, const xml_node *n, drift_result code,
                             const char *what, const char *detail);
// Logs that the element is not supported (what says why); it is ignored.
void drift__mts_warn(mitsuba_state *s, const xml_node *n, const char *what);
// Up to n numbers separated by commas and/or spaces; returns how many were read.
int drift__mts_parse_numbers(const char *text, float *out, int n);
// The child of n whose name= is `name`, or NULL.
const xml_node *drift__mts_property(const xml_node *n, const char *name);
// <float name value> (fallback when absent); an unreadable value is an error.
drift_result drift__mts_read_float(mitsuba_state *s, const xml_node *n, const char *name,
                                   float fallback, float *out);
// <rgb value="r, g, b"/>, <spectrum value="v"/> (grey) or <float value/>; *found whether given.
drift_result drift__mts_read_color(mitsuba_state *s, const xml_node *n, const char *name,
                                   drift_vec3 fallback, drift_vec3 *out, bool *found);
// A <bsdf> (with an id=, kept for <ref>) as a scene material (scene_mitsuba_bsdf.c).
drift_result drift__mts_add_bsdf(mitsuba_state *s, const xml_node *b, uint32_t *out_material);

#endif
