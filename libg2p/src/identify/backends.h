// Private: factories of the built-in identifiers, registered in
// identifier_registry(), and what several of them share.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "g2p/identify.h"

namespace g2p::detail {

std::unique_ptr<Identifier> make_detector_identifier();    // detector_identifier.cpp
std::unique_ptr<Identifier> make_classifier_identifier();  // classifier_identifier.cpp
std::unique_ptr<Identifier> make_vlm_identifier();         // vlm_identifier.cpp

// identify_views.cpp: views for networks trained on photographs.
//
// `count` views around the object from `elevation_deg` above its middle (eye
// level: photographs of objects are taken from about there, and views from
// straight above or below are hard to read), width x height pixels, on a
// background of grey `background` (0-255; -1 = the renderer's), lit by
// `lights` (empty = studio_lights()), each handed to `use` in turn (one View,
// its memory reused); an error from `use` stops the loop and is returned.
// `who` names the backend in errors.
Status for_each_turntable_view(const Renderer& renderer, const Mesh& mesh, int width, int height, int background,
                               int count, double elevation_deg, const char* who,
                               const std::function<Status(const View&)>& use,
                               const std::vector<CameraLight>& lights = {});

// The box of the object's pixels in a view (its face IDs), {x1, y1, x2, y2}
// with x2, y2 one past the last pixel; the whole view when it has no face
// IDs; empty (x2 <= x1) when the object is not in it.
struct PixelBox {
  int x1 = 0, y1 = 0, x2 = 0, y2 = 0;
  bool empty() const { return x2 <= x1 || y2 <= y1; }
};
PixelBox object_box(const View& view);

// The view's RGB with every pixel that shows no face (the background) set to
// grey `background` (0-255; < 0 keeps it as rendered), as an OpenCV-ready
// 8-bit, 3-channel RGB buffer of width x height x 3 bytes.
std::vector<std::uint8_t> rgb_on_background(const View& view, int background);

// wordnet_kinds.cpp: the kind of the shipped object table a WordNet 3.0 noun
// synset falls under (libg2p/data/wordnet_kinds.json, built with the table),
// by the synset's offset (ImageNet's "n03376595" is offset 3376595); "" when
// none. Parsed on first use.
const std::string& shipped_wordnet_kind(long offset);

}  // namespace g2p::detail
