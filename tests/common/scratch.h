/* A scratch folder for a test program's files, under the build folder. */
#ifndef SPN_TEST_SCRATCH_H
#define SPN_TEST_SCRATCH_H

#include <stddef.h>

/* Make SPN_BUILD_DIR/<prefix>_XXXXXX into `folder` (n bytes); 0 on success,
 * as cmocka's group setup wants. */
int spn_test_scratch_make(char *folder, size_t n, const char *prefix);
/* Remove the folder and everything in it; 0 on success. */
int spn_test_scratch_remove(const char *folder);

#endif
