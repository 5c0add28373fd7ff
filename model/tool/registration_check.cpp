#include "model/tool/registration_check.h"

#include "engine/check.h"
#include "io/geometry/nearest.h"

namespace jsa {

namespace {

// Mean over t's vertices of |x_t(back(there(v))) - x_t(v)|.
double round_trip(const Block<double>& x_t, const std::vector<int>& there,
                  const std::vector<int>& back) {
  double sum = 0;
  for (Index v = 0; v < x_t.rows(); ++v)
    sum += (x_t.row(back[size_t(there[size_t(v)])]) - x_t.row(v)).norm();
  return sum / double(std::max<Index>(x_t.rows(), 1));
}

}  // namespace

RegistrationCheck check_registration(const std::vector<Mesh>& meshes,
                                     const std::vector<Normalization>& frames, int t, double ratio,
                                     const SpectralStartOptions& o) {
  const size_t n = meshes.size();
  JSA_CHECK(n >= 2 && frames.size() == n && t >= 0 && size_t(t) < n,
            "check_registration: two or more meshes, one frame each, and a template among them");
  const std::vector<LaplaceBasis> bases = laplace_bases(meshes, o.functions, "--auto-register");
  RegistrationCheck c;
  c.start = spectral_start(meshes, frames, t, o, &bases);
  const Block<double>& x_t = c.start.template_vertices;
  const ZoomOutOptions zo = zoomout_options(o);  // without the prior (it anchors on t)
  c.spectral_trip.assign(n, 0.0);
  c.spatial_trip.assign(n, 0.0);
  for (size_t i = 0; i < n; ++i) {
    if (int(i) == t) continue;
    const Block<double> x_i = frames[i].to_unit(meshes[i].vertices);
    std::vector<int> there, back;
    nearest(x_t, x_i, there);
    nearest(x_i, x_t, back);
    c.spatial_trip[i] = round_trip(x_t, there, back);
    // T_ti as the registration has it (each template vertex's image is a
    // vertex of i), T_it by ZoomOut on i's vertices from the nearest start.
    std::vector<int> registered;
    nearest(c.start.images[i], x_i, registered);
    back = zoomout(bases[size_t(t)], bases[i], back, zo);
    c.spectral_trip[i] = round_trip(x_t, registered, back);
    c.spectral += c.spectral_trip[i] / double(n - 1);
    c.spatial += c.spatial_trip[i] / double(n - 1);
  }
  c.trusted = c.spectral <= ratio * c.spatial;
  return c;
}

}  // namespace jsa
