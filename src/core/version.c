// drift_version(): the version of the library the program loaded (include/drift/version.h).
#include "drift/version.h"

const char *drift_version(void)
{
    return DRIFT_VERSION;
}
