#include "model/tool/checkpoint.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "io/atomic_write.h"
#include "model/tool/fit_config.h"

namespace jsa {
namespace {

using nlohmann::json;

constexpr char kMagic[12] = {'J', 'S', 'A', 'T', 'L', 'A', 'S', '-', 'C', 'K', 'P', 'T'};
constexpr uint32_t kVersion = 2;
constexpr size_t kNameBytes = 16;
constexpr size_t kEntryBytes = kNameBytes + 2 * sizeof(uint64_t);
// Every section a checkpoint must hold, in the order they are written.
const char* const kSections[] = {"inputs",    "settings", "normalisation", "parameters",
                                 "optimiser", "rng",      "iteration"};

uint64_t fnv1a(const char* p, size_t n) {
  uint64_t h = 1469598103934665603ull;
  for (size_t i = 0; i < n; ++i) {
    h ^= uint8_t(p[i]);
    h *= 1099511628211ull;
  }
  return h;
}

template <class T>
void append(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

}  // namespace

uint64_t checkpoint_checksum(const char* data, size_t size) { return fnv1a(data, size); }

void write_checkpoint(const std::string& path, const std::vector<std::string>& inputs,
                      const FitOptions& options, const std::vector<Normalization>& normalizations,
                      const Trainer& trainer) {
  JSA_CHECK(inputs.size() == normalizations.size() && !inputs.empty(),
            "one normalisation per input");
  json frames = json::array();
  for (const Normalization& n : normalizations) {
    json rotation = json::array();  // rows, as io/geometry/normalization.h applies it
    for (int r = 0; r < 3; ++r)
      rotation.push_back({n.rotation(r, 0), n.rotation(r, 1), n.rotation(r, 2)});
    frames.push_back(json{{"center", {n.center(0), n.center(1), n.center(2)}},
                          {"scale", n.scale},
                          {"rotation", rotation}});
  }
  const TrainerState state = trainer.save_state();
  const std::map<std::string, std::string> payload = {
      {"inputs", json(inputs).dump()},  {"settings", fit_options_to_json(options, -1)},
      {"normalisation", frames.dump()}, {"parameters", state.parameters},
      {"optimiser", state.optimiser},   {"rng", state.rng},
      {"iteration", state.progress}};
  const uint32_t count = uint32_t(std::size(kSections));
  std::string body(kMagic, sizeof kMagic);
  append(body, kVersion);
  append(body, count);
  uint64_t offset = body.size() + count * kEntryBytes;
  for (const char* name : kSections) {
    std::string padded(name);
    JSA_CHECK(padded.size() < kNameBytes, "checkpoint section name too long: " << name);
    padded.resize(kNameBytes, '\0');
    body.append(padded);
    const uint64_t size = payload.at(name).size();
    append(body, offset);
    append(body, size);
    offset += size;
  }
  for (const char* name : kSections) body.append(payload.at(name));
  append(body, fnv1a(body.data(), body.size()));
  write_file_atomically(
      path, [&](std::ostream& out) { out.write(body.data(), std::streamsize(body.size())); });
}

CheckpointContents read_checkpoint(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open checkpoint");
  std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (data.size() < sizeof kMagic + sizeof kVersion ||
      std::memcmp(data.data(), kMagic, sizeof kMagic) != 0)
    throw InputError(path + ": not a jsatlas checkpoint");
  uint32_t version = 0;
  std::memcpy(&version, data.data() + sizeof kMagic, sizeof version);
  if (version != kVersion)
    throw InputError(
        path + ": checkpoint format " + std::to_string(version) + ", this build reads format " +
        std::to_string(kVersion) +
        " only (the format changed to named sections; refit, or use the jsatlas that wrote it)");
  uint64_t stored = 0;
  if (data.size() < sizeof kMagic + sizeof kVersion + sizeof(uint32_t) + sizeof stored)
    throw InputError(path + ": checkpoint is truncated");
  std::memcpy(&stored, data.data() + data.size() - sizeof stored, sizeof stored);
  const size_t end = data.size() - sizeof stored;
  if (fnv1a(data.data(), end) != stored)
    throw InputError(path + ": checkpoint is corrupted or truncated (checksum mismatch)");

  // The table of contents: every section inside the file, back to back, no repeats.
  size_t at = sizeof kMagic + sizeof kVersion;
  uint32_t count = 0;
  std::memcpy(&count, data.data() + at, sizeof count);
  at += sizeof count;
  if (count > 64 || (end - at) / kEntryBytes < count)
    throw InputError(path + ": bad checkpoint table of contents");
  std::map<std::string, std::string> sections;
  uint64_t next = at + count * kEntryBytes;
  for (uint32_t k = 0; k < count; ++k, at += kEntryBytes) {
    const char* entry = data.data() + at;
    const std::string name(entry, strnlen(entry, kNameBytes));
    uint64_t offset = 0, size = 0;
    std::memcpy(&offset, entry + kNameBytes, sizeof offset);
    std::memcpy(&size, entry + kNameBytes + sizeof offset, sizeof size);
    if (offset != next || size > end - offset)
      throw InputError(path + ": checkpoint section '" + name + "' overruns the file");
    if (!sections.emplace(name, data.substr(offset, size)).second)
      throw InputError(path + ": checkpoint section '" + name + "' appears twice");
    next = offset + size;
  }
  if (next != end) throw InputError(path + ": trailing bytes in checkpoint");
  for (const char* name : kSections)
    if (!sections.count(name))
      throw InputError(path + ": checkpoint lacks the section '" + std::string(name) + "'");

  CheckpointContents c;
  try {
    const json inputs = json::parse(sections.at("inputs"));
    if (!inputs.is_array() || inputs.empty() || inputs.size() > 100000)
      throw std::runtime_error("one input per shape");
    for (const json& i : inputs) c.inputs.push_back(i.get<std::string>());
    const json frames = json::parse(sections.at("normalisation"));
    if (!frames.is_array() || frames.size() != inputs.size())
      throw std::runtime_error("one frame per input");
    for (const json& f : frames) {
      const json& center = f.at("center");
      if (!center.is_array() || center.size() != 3)
        throw std::runtime_error("a center has 3 coordinates");
      Normalization n;
      n.center = Eigen::RowVector3d(center[0].get<double>(), center[1].get<double>(),
                                    center[2].get<double>());
      n.scale = f.at("scale").get<double>();
      if (!(n.scale > 0) || !std::isfinite(n.scale) || !n.center.allFinite())
        throw std::runtime_error("bad frame");
      // The shape's pose (collections, io/geometry/rigid_align.h); a frame
      // without one (written before the pose step) is in the input's pose.
      if (f.contains("rotation")) {
        const json& rows = f.at("rotation");
        if (!rows.is_array() || rows.size() != 3) throw std::runtime_error("a rotation is 3 x 3");
        for (int r = 0; r < 3; ++r) {
          if (!rows[size_t(r)].is_array() || rows[size_t(r)].size() != 3)
            throw std::runtime_error("a rotation is 3 x 3");
          for (int k = 0; k < 3; ++k) n.rotation(r, k) = rows[size_t(r)][size_t(k)].get<double>();
        }
        const bool proper = n.rotation.allFinite() &&
                            (n.rotation * n.rotation.transpose() - Eigen::Matrix3d::Identity())
                                    .cwiseAbs()
                                    .maxCoeff() < 1e-6 &&
                            n.rotation.determinant() > 0;
        if (!proper) throw std::runtime_error("bad rotation");
      }
      c.normalizations.push_back(n);
    }
  } catch (const std::exception& e) {
    throw InputError(path + ": bad inputs or normalisation in checkpoint (" + e.what() + ")");
  }
  c.settings_json = sections.at("settings");
  c.state.parameters = sections.at("parameters");
  c.state.optimiser = sections.at("optimiser");
  c.state.rng = sections.at("rng");
  c.state.progress = sections.at("iteration");
  return c;
}

void restore_trainer(Trainer& trainer, const CheckpointContents& contents,
                     const std::string& path) {
  trainer.load_state(contents.state, path);
}

std::unique_ptr<Atlas<float>> load_atlas(const CheckpointContents& contents,
                                         const std::string& path) {
  const FitOptions o = fit_options_from_json(contents.settings_json, path);
  AtlasOptions ao = o.atlas;
  ao.gaussian_noise = o.components.distribution;
  auto atlas = std::make_unique<Atlas<float>>(ao);
  std::istringstream parameters(contents.state.parameters);
  atlas->params.load(parameters, path);
  return atlas;
}

}  // namespace jsa
