// Umbrella header: the whole public API of libg2p.
#pragma once

#include "g2p/complete.h"
#include "g2p/eval.h"
#include "g2p/image.h"
#include "g2p/io.h"
#include "g2p/materials.h"
#include "g2p/mesh.h"
#include "g2p/model.h"
#include "g2p/project.h"
#include "g2p/properties.h"
#include "g2p/refine.h"
#include "g2p/registry.h"
#include "g2p/render.h"
#include "g2p/segment.h"
#include "g2p/status.h"
#include "g2p/version.h"
#include "g2p/vlm.h"
