// complete_cgal: the CGAL-based completers of stage 5, in the optional
// component g2p::cgal (library g2p_cgal, built when G2P_WITH_CGAL=ON).
//
// Licence: this component is GPL-3.0-or-later, because it uses CGAL's GPL
// packages (Alpha_wrap_3, Polygon Mesh Processing). A program that links
// g2p::cgal is distributed under GPL-3.0-or-later as a whole; libg2p itself
// (g2p::g2p) stays Apache-2.0 and contains no CGAL code. See
// docs/licensing.md. Link g2p::cgal to get these backends:
//
//   target_link_libraries(app PRIVATE g2p::cgal)  // after find_package(g2p COMPONENTS cgal)
//
// Backends:
//   "alpha-wrap"  CGAL::alpha_wrap_3 of each part's patch: always watertight,
//                 manifold and free of self-intersections. Settings:
//                 relative_alpha (default 0.01) and relative_offset (default
//                 0.0005), both relative to the part's bounding-box diagonal;
//                 max_relative_distance (default 0.25). The wrap lies about
//                 the offset outside the patch, so a closed part gains about
//                 its area times the offset in volume. An open patch whose
//                 holes are wider than about 2 alpha is wrapped as a thin
//                 shell around both sides of its surface (watertight, but
//                 with almost no volume; the part's notes say so).
//   "fill"        fills each hole of the part's patch with
//                 Polygon_mesh_processing::triangulate_refine_and_fair_hole.
//                 Settings: max_relative_hole (default 0.3: a part whose
//                 largest hole spans more than this fraction of the patch's
//                 bounding-box diagonal is not filled), fairing_continuity
//                 (0, 1 or 2; default 1), max_relative_distance (default
//                 0.25). Parts it cannot close are left not ok, so
//                 complete() redoes them with its fallback.
#pragma once

#include <memory>

#include "g2p/complete.h"
#include "g2p/status.h"

#if defined(G2P_STATIC)
#define G2P_CGAL_API
#elif defined(_WIN32)
#if defined(G2P_CGAL_BUILDING)
#define G2P_CGAL_API __declspec(dllexport)
#else
#define G2P_CGAL_API __declspec(dllimport)
#endif
#else
#define G2P_CGAL_API [[gnu::visibility("default")]]
#endif

namespace g2p {

// Adds "alpha-wrap" and "fill" to completer_registry(). Idempotent: names
// that are already registered are left as they are.
G2P_CGAL_API Status register_cgal_completers();

// New, unconfigured instances (call configure() for settings).
G2P_CGAL_API std::unique_ptr<Completer> make_alpha_wrap_completer();
G2P_CGAL_API std::unique_ptr<Completer> make_fill_completer();

}  // namespace g2p
