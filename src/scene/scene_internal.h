// Private to src/scene: pieces shared between scene.c and the light/BSDF code.
#ifndef DRIFT_SCENE_INTERNAL_H
#define DRIFT_SCENE_INTERNAL_H

#include "drift/scene.h"

// Builds scene->light_table (power distribution over lights and the environment).
drift_result drift__light_table_build(drift_scene *scene);
void drift__light_table_destroy(drift_scene *scene);

#endif
