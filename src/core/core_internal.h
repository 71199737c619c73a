/* Shared between files of src/core. */
#ifndef SPN_CORE_INTERNAL_H
#define SPN_CORE_INTERNAL_H

/* Temporary output files that a fatal signal must remove (interrupt.c);
 * spn_atomic_open tracks, commit and abort untrack. The string must live
 * until untracked. */
void spn__temp_track(const char *tmp_path);
void spn__temp_untrack(const char *tmp_path);

#endif
