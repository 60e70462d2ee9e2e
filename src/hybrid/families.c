// The technique families, in the order the conductor calls their hooks. The order matters in
// one place: after a shadow row, ssdo's contact shadows refine S_l before realtime sums D
// (both are after_row hooks), so ssdo comes first. A new family is one line here and its
// folder's family.c (docs/adding-a-technique.md).
#include "hybrid/families.h"

static const drift_family *const families[] = {
    &drift_ssdo_family, &drift_realtime_family, &drift_isg_family,   &drift_aaf_family,
    &drift_ism_family,  &drift_micro_family,    &drift_glare_family,
};

const drift_family *drift_family_at(int index)
{
    return index >= 0 && index < (int)(sizeof families / sizeof *families) ? families[index] : NULL;
}
