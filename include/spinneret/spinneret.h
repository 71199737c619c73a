/* Spinneret: build, simulate, animate and render spider webs. Include this
 * one header for the whole public API. */
#ifndef SPINNERET_H
#define SPINNERET_H

#include "core.h"
#include "world.h"
#include "web.h"
#include "io.h"
#include "scenes.h"
#include "equilibrium.h"
#include "render.h"
#include "anim.h"
#include "export.h"
#include "mesh.h"
#include "shoot.h"
#include "inscribe.h"

#endif
