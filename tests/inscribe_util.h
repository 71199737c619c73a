/* The web the inscription tests write on: the standard orb web, stepped
 * symplectically with enough drag that settling after pruning is quick.
 * Include after cmocka.h (it asserts). */
#ifndef SPN_TEST_INSCRIBE_UTIL_H
#define SPN_TEST_INSCRIBE_UTIL_H

#include <spinneret/spinneret.h>

static inline spn_world *inscribe_orb(void)
{
    spn_world_def wd = spn_world_def_default();
    wd.integrator = SPN_INTEGRATOR_SYMPLECTIC;
    wd.drag = 200;
    spn_world *w = NULL;
    assert_int_equal(spn_scene_orb(&wd, NULL, &w), SPN_OK);
    return w;
}

#endif
