#include "model/checkpoint.h"

#include <cstdint>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>

#include "io/atomic_write.h"
#include "model/fit_config.h"

namespace jsa {
namespace {

constexpr char kMagic[12] = {'J', 'S', 'A', 'T', 'L', 'A', 'S', '-', 'C', 'K', 'P', 'T'};
// Version 2 adds each shape's rotation (io/normalization.h) after its centre and
// scale; version 1 files are read with the identity.
constexpr uint32_t kVersion = 2;

uint64_t fnv1a(const char* p, size_t n) {
  uint64_t h = 1469598103934665603ull;
  for (size_t i = 0; i < n; ++i) {
    h ^= uint8_t(p[i]);
    h *= 1099511628211ull;
  }
  return h;
}

void put_string(std::string& out, const std::string& s) {
  const uint64_t n = s.size();
  out.append(reinterpret_cast<const char*>(&n), sizeof n);
  out.append(s);
}

}  // namespace

void write_checkpoint(const std::string& path, const std::vector<std::string>& inputs,
                      const FitOptions& options, const std::vector<Normalization>& normalizations,
                      const Trainer& trainer) {
  JSA_CHECK(inputs.size() == normalizations.size() && !inputs.empty(),
            "one normalisation per input");
  std::string body(kMagic, sizeof kMagic);
  body.append(reinterpret_cast<const char*>(&kVersion), sizeof kVersion);
  const uint64_t count = inputs.size();
  body.append(reinterpret_cast<const char*>(&count), sizeof count);
  for (const std::string& input : inputs) put_string(body, input);
  put_string(body, fit_options_to_json(options, -1));
  for (const Normalization& n : normalizations) {
    double norm[13] = {n.center(0), n.center(1), n.center(2), n.scale};
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) norm[4 + 3 * r + c] = n.rotation(r, c);
    body.append(reinterpret_cast<const char*>(norm), sizeof norm);
  }
  std::ostringstream state;
  trainer.save_state(state);
  put_string(body, state.str());
  const uint64_t sum = fnv1a(body.data(), body.size());
  body.append(reinterpret_cast<const char*>(&sum), sizeof sum);
  write_file_atomically(
      path, [&](std::ostream& out) { out.write(body.data(), std::streamsize(body.size())); });
}

CheckpointContents read_checkpoint(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open checkpoint");
  std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t min_size = sizeof kMagic + sizeof kVersion + sizeof(uint64_t);
  if (data.size() < min_size || std::memcmp(data.data(), kMagic, sizeof kMagic) != 0)
    throw InputError(path + ": not a jsatlas checkpoint");
  uint64_t stored = 0;
  std::memcpy(&stored, data.data() + data.size() - sizeof stored, sizeof stored);
  if (fnv1a(data.data(), data.size() - sizeof stored) != stored)
    throw InputError(path + ": checkpoint is corrupted or truncated (checksum mismatch)");
  size_t at = sizeof kMagic;
  const size_t end = data.size() - sizeof stored;
  auto take = [&](void* p, size_t n) {
    if (end - at < n) throw InputError(path + ": checkpoint section overruns the file");
    std::memcpy(p, data.data() + at, n);
    at += n;
  };
  auto take_string = [&]() {
    uint64_t n = 0;
    take(&n, sizeof n);
    if (n > end - at) throw InputError(path + ": checkpoint section overruns the file");
    std::string s(data.data() + at, n);
    at += n;
    return s;
  };
  uint32_t version = 0;
  take(&version, sizeof version);
  if (version != kVersion && version != 1)
    throw InputError(path + ": checkpoint format " + std::to_string(version) +
                     ", this build reads 1 to " + std::to_string(kVersion));
  CheckpointContents c;
  uint64_t count = 0;
  take(&count, sizeof count);
  if (count == 0 || count > 100000)
    throw InputError(path + ": implausible shape count in checkpoint");
  for (uint64_t i = 0; i < count; ++i) c.inputs.push_back(take_string());
  c.settings_json = take_string();
  for (uint64_t i = 0; i < count; ++i) {
    double norm[13];
    take(norm, sizeof(double) * (version == 1 ? 4 : 13));
    Normalization n;
    n.center = Eigen::RowVector3d(norm[0], norm[1], norm[2]);
    n.scale = norm[3];
    if (!(n.scale > 0) || !n.center.allFinite())
      throw InputError(path + ": bad normalisation in checkpoint");
    if (version >= 2) {
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) n.rotation(r, c) = norm[4 + 3 * r + c];
      const bool rotation = n.rotation.allFinite() &&
                            (n.rotation * n.rotation.transpose() - Eigen::Matrix3d::Identity())
                                    .cwiseAbs()
                                    .maxCoeff() < 1e-6 &&
                            n.rotation.determinant() > 0;
      if (!rotation) throw InputError(path + ": bad rotation in checkpoint");
    }
    c.normalizations.push_back(n);
  }
  c.state = take_string();
  if (at != end) throw InputError(path + ": trailing bytes in checkpoint");
  return c;
}

void restore_trainer(Trainer& trainer, const CheckpointContents& contents,
                     const std::string& path) {
  std::istringstream state(contents.state);
  trainer.load_state(state, path);
}

std::unique_ptr<Atlas<float>> load_atlas(const CheckpointContents& contents,
                                         const std::string& path) {
  const FitOptions o = fit_options_from_json(contents.settings_json, path);
  AtlasOptions ao = o.atlas;
  ao.gaussian_noise = o.components.distribution;
  auto atlas = std::make_unique<Atlas<float>>(ao);
  // Trainer::save_state: i64 iteration, 4 x u64 RNG, i64 Adam steps, f64 lr scale, parameters.
  std::istringstream state(contents.state);
  state.seekg(8 + 32 + 8 + 8);
  atlas->params.load(state, path);
  return atlas;
}

}  // namespace jsa
