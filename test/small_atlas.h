// Shared by the model tests: an atlas small enough for central differences
// and for fits of a few hundred steps inside a test.
#pragma once
#include "model/atlas.h"

namespace test_support {

// 16 Gaussians; phi and psi with 2 hidden layers of `width`.
inline jsa::AtlasOptions small_atlas(int width) {
  jsa::AtlasOptions o;
  o.gaussians = 16;
  o.width = width;
  o.hidden_layers = 2;
  return o;
}

}  // namespace test_support
