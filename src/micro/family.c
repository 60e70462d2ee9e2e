// Micro-rendering's hooks (frame/family.h). Its drift_micro (points, hierarchy) lives in each
// effect's state slot across frames (micro_pass.c).
#include "frame/family.h"

#include "micro/micro_pass.h"

const drift_family drift_micro_family = {
    .name = "micro",
};
