// A colour, RGBA in [0, 1]: the one render type that scene descriptions hold (styles), kept in
// a header of its own so that they need nothing else of the renderer.
#pragma once

namespace flexure::render {

struct Color {
  float r = 0, g = 0, b = 0, a = 1;
};

}  // namespace flexure::render
