#include "common/scratch.h"

#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

int spn_test_scratch_make(char *folder, size_t n, const char *prefix)
{
    snprintf(folder, n, "%s/%s_XXXXXX", SPN_BUILD_DIR, prefix);
    return mkdtemp(folder) ? 0 : -1;
}

int spn_test_scratch_remove(const char *folder)
{
    char cmd[1100];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", folder);
    return system(cmd) == 0 ? 0 : -1;
}
