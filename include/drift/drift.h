// drift: every public header at once. A program may include only the ones it uses.
#ifndef DRIFT_DRIFT_H
#define DRIFT_DRIFT_H

#include "drift/accel.h"
#include "drift/bind.h"
#include "drift/core.h"
#include "drift/denoise.h"
#include "drift/glare.h"
#include "drift/hybrid.h"
#include "drift/image.h"
#include "drift/image_io.h"
#include "drift/ism.h"
#include "drift/math.h"
#include "drift/metric.h"
#include "drift/micro.h"
#include "drift/points.h"
#include "drift/pt.h"
#include "drift/refine.h"
#include "drift/reflect_edit.h"
#include "drift/scene.h"
#include "drift/scene_io.h"
#include "drift/ssdo.h"
#include "drift/techniques.h"
#include "drift/version.h"
#include "drift/view.h"

#endif
