// Private to scene_mitsuba.c and scene_mitsuba3.c: the element tree expat's reading leaves.
#ifndef DRIFT_SCENE_MITSUBA_XML_H
#define DRIFT_SCENE_MITSUBA_XML_H

#include "drift/core.h"

typedef struct xml_node {
    char *name;
    char **attrs; // name, value, name, value, ..., NULL (from drift_alloc)
    int line;
    struct xml_node *parent, *first, *last, *next;
} xml_node;

// Brings a Mitsuba 3 scene (<scene version="3...">) to the Mitsuba 0.6 form scene_mitsuba.c
// reads, in place: <default name value> parameters and $name substitution in every attribute,
// snake_case property names (to_world, fov_axis, cutoff_angle, ...) as 0.6's camelCase,
// "x, y, z" values of <point>, <vector>, <translate> and <rotate> as x/y/z attributes, and the
// v3 plugin names as their 0.6 counterparts. A 0.6 scene passes through unchanged. Errors (a
// $name with no <default>, out of memory) are logged against path and the element's line.
drift_result drift__mitsuba3_normalize(drift_context *ctx, const char *path, xml_node *root);

#endif
