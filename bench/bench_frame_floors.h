// drift bench frame --floors (bench_frame_floors.c): each image pass against its bandwidth
// floor, measured in the same run.
#ifndef DRIFT_BENCH_FRAME_FLOORS_H
#define DRIFT_BENCH_FRAME_FLOORS_H

#include "drift/accel.h"
#include "drift/scene.h"

#include <stdbool.h>

typedef struct bench_floor_options {
    long width, height, repeats;
    bool json;
    const char *passes; // comma-separated pass names to time (NULL: all)
} bench_floor_options;

// Renders the frames, times the passes and prints the table (or JSON). Returns the exit status.
int bench_frame_floors(drift_context *ctx, const drift_scene *scene, const drift_accel *accel,
                       const char *scene_path, const bench_floor_options *o);

#endif // DRIFT_BENCH_FRAME_FLOORS_H
