// Glare's hooks (frame/family.h). Its PSFs live in the glare effect's state slot across
// frames (glare_pass.c).
#include "frame/family.h"

#include "glare/glare_pass.h"

const drift_family drift_glare_family = {
    .name = "glare",
};
