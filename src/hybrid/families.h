// The conductor's list of technique families (frame/family.h): the frame creates, updates,
// reports and frees every family's state by walking this list, never by naming a family.
#ifndef DRIFT_HYBRID_FAMILIES_H
#define DRIFT_HYBRID_FAMILIES_H

#include "frame/family.h"

// The families in the order their hooks run, or NULL past the last.
const drift_family *drift_family_at(int index);

#endif // DRIFT_HYBRID_FAMILIES_H
