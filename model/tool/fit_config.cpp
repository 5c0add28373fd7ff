#include "model/tool/fit_config.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <type_traits>

namespace jsa {

using nlohmann::json;

namespace {

// Whether the JSON number `value` fits the integer type T. nlohmann's get_to
// converts with static_cast: undefined behaviour for 1e300 into an int (UBSan in
// fuzz_fit_config), a silent wrap for 10^10. Non-numbers and non-integer T pass
// here; get_to reports a wrong type itself.
template <class T>
bool fits(const json& value) {
  if constexpr (!std::is_integral_v<T> || std::is_same_v<T, bool>) {
    return true;
  } else {
    using Limits = std::numeric_limits<T>;
    if (value.is_number_float()) {
      const double d = value.get<double>();
      const double bound = std::ldexp(1.0, Limits::digits);  // 2^31 for int, 2^64 for uint64_t
      return d == std::floor(d) && d < bound && d >= (Limits::is_signed ? -bound : 0.0);
    }
    if (value.is_number_unsigned())
      return value.get<std::uint64_t>() <= std::uint64_t(Limits::max());
    if (value.is_number_integer()) {
      const std::int64_t v = value.get<std::int64_t>();
      if (v < 0) return Limits::is_signed && v >= std::int64_t(Limits::min());
      return std::uint64_t(v) <= std::uint64_t(Limits::max());
    }
    return true;
  }
}

}  // namespace

std::string fit_options_to_json(const FitOptions& o, int indent) {
  json j;
  j["atlas"] = {{"gaussians", o.atlas.gaussians},
                {"width", o.atlas.width},
                {"chart_width", o.atlas.chart_width},
                {"chart_fourier", o.atlas.chart_fourier},
                {"chart_fourier_sigma", o.atlas.chart_fourier_sigma},
                {"hidden_layers", o.atlas.hidden_layers},
                {"alpha", o.atlas.alpha},
                {"shapes", o.atlas.shapes},
                {"code_size", o.atlas.code_size},
                {"code_layer", o.atlas.code_layer},
                {"softplus_beta", o.atlas.softplus_beta},
                {"deform_layers", o.atlas.deform_layers},
                {"deform_domain", o.atlas.deform_domain},
                {"deform_nodes", o.atlas.deform_nodes},
                {"fine_nodes", o.atlas.fine_nodes}};
  j["weights"] = {{"surface_6d", o.weights.surface},
                  {"chart_2d", o.weights.chart},
                  {"cycle", o.weights.cycle},
                  {"isometry", o.weights.isometry},
                  {"repulsion", o.weights.repulsion},
                  {"code", o.weights.code},
                  {"metric", o.weights.metric},
                  {"evenness", o.weights.evenness},
                  {"transport", o.weights.transport},
                  {"coverage", o.weights.coverage},
                  {"convention", "mean over points (paper's 1/M factors folded in)"}};
  j["components"] = {{"normals", o.components.normals},
                     {"repulsion", o.components.repulsion},
                     {"distribution", o.components.distribution},
                     {"chart", o.components.chart},
                     {"isometry", o.components.isometry}};
  j["iterations"] = o.iterations;
  j["points"] = o.points;
  j["lr"] = o.lr;
  j["decay_at"] = o.decay_at;
  j["decay"] = o.decay;
  j["schedule"] = {{"kind", o.schedule.kind},
                   {"points_start", o.schedule.points_start},
                   {"ramp_until", o.schedule.ramp_until},
                   {"levels", o.schedule.levels},
                   {"warmup", o.schedule.warmup},
                   {"drop_at", o.schedule.drop_at},
                   {"drop", o.schedule.drop}};
  j["seed"] = o.seed;
  j["repulsion_tolerance"] = o.repulsion_tolerance;
  j["max_faults"] = o.max_faults;
  j["fault_lr_factor"] = o.fault_lr_factor;
  j["orient_every"] = o.orient_every;
  j["batch_shapes"] = o.batch_shapes;
  j["wrap_steps"] = o.wrap_steps;
  j["reseed_every"] = o.reseed_every;
  j["dense_surface"] = o.dense_surface;
  j["template_steps"] = o.template_steps;
  j["template_shape"] = o.template_shape;
  j["align_poses"] = o.align_poses;
  j["pose_fit_steps"] = o.pose_fit_steps;
  j["template_share"] = o.template_share;
  j["template_max_steps"] = o.template_max_steps;
  j["chart_from"] = o.chart_from;
  j["evenness_from"] = o.evenness_from;
  j["transport_from"] = o.transport_from;
  j["transport_points"] = o.transport_points;
  j["metric_end"] = o.metric_end;
  j["metric_until"] = o.metric_until;
  j["metric_conformal"] = o.metric_conformal;
  j["code_lr_scale"] = o.code_lr_scale;
  j["surface_lr_scale"] = o.surface_lr_scale;
  j["intrinsic"] = o.intrinsic;
  j["intrinsic_until"] = o.intrinsic_until;
  j["spectral_map"] = o.spectral_map;
  j["spectral_map_until"] = o.spectral_map_until;
  j["template_coverage"] = o.template_coverage;
  j["register_nodes"] = o.register_nodes;
  j["register_prior"] = o.register_prior;
  j["nodes_lr_scale"] = o.nodes_lr_scale;
  j["auto_register"] = o.auto_register;
  j["nodes_width"] = o.nodes_width;
  j["fine_width"] = o.fine_width;
  j["parallel_shapes"] = o.parallel_shapes;
  j["pool"] = o.pool;
  j["threads"] = o.threads;
  j["gemm"] = gemm_name(o.gemm);
  return j.dump(indent);
}

FitOptions fit_options_from_json(const std::string& text, const std::string& what) {
  json j;
  try {
    j = json::parse(text);
  } catch (const std::exception& e) {
    throw InputError(what + ": not valid JSON (" + e.what() + ")");
  }
  FitOptions o;
  auto field = [&](const json& obj, const char* path, const char* key, auto& out) {
    if (!obj.is_object() || !obj.contains(key))
      throw InputError(what + ": missing field '" + std::string(path) + key + "'");
    if (!fits<std::decay_t<decltype(out)>>(obj.at(key)))
      throw InputError(what + ": field '" + std::string(path) + key + "' is out of range");
    try {
      obj.at(key).get_to(out);
    } catch (const std::exception&) {
      throw InputError(what + ": field '" + std::string(path) + key + "' has the wrong type");
    }
  };
  if (!j.is_object()) throw InputError(what + ": expected a JSON object");
  const json& a = j.contains("atlas") ? j["atlas"] : json();
  field(a, "atlas.", "gaussians", o.atlas.gaussians);
  field(a, "atlas.", "width", o.atlas.width);
  o.atlas.chart_width = 0;  // later addition: absent = psi as wide as phi
  if (a.contains("chart_width")) field(a, "atlas.", "chart_width", o.atlas.chart_width);
  o.atlas.chart_fourier = 0;  // later additions: absent = the paper's psi
  o.atlas.chart_fourier_sigma = AtlasOptions{}.chart_fourier_sigma;
  if (a.contains("chart_fourier")) field(a, "atlas.", "chart_fourier", o.atlas.chart_fourier);
  if (a.contains("chart_fourier_sigma"))
    field(a, "atlas.", "chart_fourier_sigma", o.atlas.chart_fourier_sigma);
  if (o.atlas.chart_fourier < 0 || o.atlas.chart_fourier > 4096 ||
      !(o.atlas.chart_fourier_sigma > 0) || !std::isfinite(o.atlas.chart_fourier_sigma))
    throw InputError(what + ": atlas.chart_fourier must be in [0, 4096] and " +
                     "atlas.chart_fourier_sigma positive");
  field(a, "atlas.", "hidden_layers", o.atlas.hidden_layers);
  field(a, "atlas.", "alpha", o.atlas.alpha);
  field(a, "atlas.", "shapes", o.atlas.shapes);
  field(a, "atlas.", "code_size", o.atlas.code_size);
  if (a.contains("code_layer"))
    field(a, "atlas.", "code_layer", o.atlas.code_layer);  // later addition: absent = 0
  o.atlas.softplus_beta = 0;  // later addition: absent = ReLU, what older runs used
  if (a.contains("softplus_beta")) field(a, "atlas.", "softplus_beta", o.atlas.softplus_beta);
  o.atlas.deform_layers = 0;  // later addition: absent = the paper's phi(x, f)
  if (a.contains("deform_layers")) field(a, "atlas.", "deform_layers", o.atlas.deform_layers);
  if (o.atlas.deform_layers < 0 || o.atlas.deform_layers > 64)
    throw InputError(what + ": atlas.deform_layers must be in [0, 64]");
  o.atlas.deform_domain = false;  // later addition: absent = D(phi(x), f)
  if (a.contains("deform_domain")) field(a, "atlas.", "deform_domain", o.atlas.deform_domain);
  o.atlas.deform_nodes = 0;  // later addition: absent = none
  if (a.contains("deform_nodes")) field(a, "atlas.", "deform_nodes", o.atlas.deform_nodes);
  if (o.atlas.deform_nodes < 0 || o.atlas.deform_nodes > 4096)
    throw InputError(what + ": atlas.deform_nodes must be in [0, 4096]");
  o.atlas.fine_nodes = 0;  // later addition: absent = none
  if (a.contains("fine_nodes")) field(a, "atlas.", "fine_nodes", o.atlas.fine_nodes);
  if (o.atlas.fine_nodes < 0 || o.atlas.fine_nodes > 4096)
    throw InputError(what + ": atlas.fine_nodes must be in [0, 4096]");
  const json& w = j.contains("weights") ? j["weights"] : json();
  field(w, "weights.", "surface_6d", o.weights.surface);
  field(w, "weights.", "chart_2d", o.weights.chart);
  field(w, "weights.", "cycle", o.weights.cycle);
  field(w, "weights.", "isometry", o.weights.isometry);
  field(w, "weights.", "repulsion", o.weights.repulsion);
  field(w, "weights.", "code", o.weights.code);
  o.weights.metric = 0;  // later addition: absent = off, what older runs used
  if (w.contains("metric")) field(w, "weights.", "metric", o.weights.metric);
  o.weights.evenness = 0;  // later addition: absent = off
  if (w.contains("evenness")) field(w, "weights.", "evenness", o.weights.evenness);
  if (!(o.weights.evenness >= 0) || !std::isfinite(o.weights.evenness))
    throw InputError(what + ": weights.evenness must be finite and >= 0");
  o.weights.transport = 0;  // later addition: absent = off
  if (w.contains("transport")) field(w, "weights.", "transport", o.weights.transport);
  if (!(o.weights.transport >= 0) || !std::isfinite(o.weights.transport))
    throw InputError(what + ": weights.transport must be finite and >= 0");
  o.weights.coverage = 1;  // later addition: absent = Eq. 6's equal directions
  if (w.contains("coverage")) field(w, "weights.", "coverage", o.weights.coverage);
  if (!(o.weights.coverage >= 0) || !std::isfinite(o.weights.coverage))
    throw InputError(what + ": weights.coverage must be finite and >= 0");
  const json& c = j.contains("components") ? j["components"] : json();
  field(c, "components.", "normals", o.components.normals);
  field(c, "components.", "repulsion", o.components.repulsion);
  field(c, "components.", "distribution", o.components.distribution);
  field(c, "components.", "chart", o.components.chart);
  field(c, "components.", "isometry", o.components.isometry);
  field(j, "", "iterations", o.iterations);
  field(j, "", "points", o.points);
  field(j, "", "lr", o.lr);
  field(j, "", "decay_at", o.decay_at);
  field(j, "", "decay", o.decay);
  // Added with the ramp: a file without it comes from a run at fixed M.
  o.schedule = ScheduleOptions{};
  o.schedule.kind = "step";
  if (j.contains("schedule")) {
    const json& s = j["schedule"];
    field(s, "schedule.", "kind", o.schedule.kind);
    field(s, "schedule.", "points_start", o.schedule.points_start);
    field(s, "schedule.", "ramp_until", o.schedule.ramp_until);
    field(s, "schedule.", "levels", o.schedule.levels);
    field(s, "schedule.", "warmup", o.schedule.warmup);
    // Runs written before the drop existed have neither field: no drop.
    if (s.contains("drop_at")) field(s, "schedule.", "drop_at", o.schedule.drop_at);
    if (s.contains("drop")) field(s, "schedule.", "drop", o.schedule.drop);
    if (o.schedule.kind != "ramp" && o.schedule.kind != "step")
      throw InputError(what + ": field 'schedule.kind' must be \"ramp\" or \"step\"");
    if (!(o.schedule.points_start > 0 && o.schedule.points_start <= 1) ||
        !(o.schedule.ramp_until > 0 && o.schedule.ramp_until <= 1) || o.schedule.levels < 1 ||
        o.schedule.levels > 1000 || !(o.schedule.warmup >= 0 && o.schedule.warmup <= 1) ||
        !(o.schedule.drop_at >= 0 && o.schedule.drop_at <= 1) ||
        !(o.schedule.drop > 0 && o.schedule.drop <= 1))
      throw InputError(what + ": a field of 'schedule' is out of range");
  }
  field(j, "", "seed", o.seed);
  field(j, "", "repulsion_tolerance", o.repulsion_tolerance);
  field(j, "", "max_faults", o.max_faults);
  if (j.contains("fault_lr_factor"))
    field(j, "", "fault_lr_factor", o.fault_lr_factor);  // later addition: absent = 0.5
  // Added after the first checkpoints were written: a file without them comes
  // from a run that had neither, so absent means 0 (what that run did).
  o.orient_every = 0;
  if (j.contains("orient_every")) field(j, "", "orient_every", o.orient_every);
  if (j.contains("batch_shapes")) field(j, "", "batch_shapes", o.batch_shapes);
  o.wrap_steps = 0;
  if (j.contains("wrap_steps")) field(j, "", "wrap_steps", o.wrap_steps);
  o.reseed_every = 0;
  if (j.contains("reseed_every")) field(j, "", "reseed_every", o.reseed_every);
  o.dense_surface = false;
  if (j.contains("dense_surface")) field(j, "", "dense_surface", o.dense_surface);
  o.template_steps = 0;
  o.template_share = 0;
  o.align_poses = false;  // later addition: runs before it were not aligned
  if (j.contains("align_poses")) field(j, "", "align_poses", o.align_poses);
  o.pose_fit_steps = 0;
  if (j.contains("pose_fit_steps")) field(j, "", "pose_fit_steps", o.pose_fit_steps);
  if (o.pose_fit_steps < 0) throw InputError(what + ": pose_fit_steps must be >= 0");
  if (j.contains("template_steps")) field(j, "", "template_steps", o.template_steps);
  if (j.contains("template_share")) field(j, "", "template_share", o.template_share);
  o.code_lr_scale = 1;
  if (j.contains("code_lr_scale")) field(j, "", "code_lr_scale", o.code_lr_scale);
  if (!(o.code_lr_scale > 0) || !std::isfinite(o.code_lr_scale))
    throw InputError(what + ": code_lr_scale must be positive");
  o.surface_lr_scale = 1;  // later addition: absent = one rate
  if (j.contains("surface_lr_scale")) field(j, "", "surface_lr_scale", o.surface_lr_scale);
  if (!(o.surface_lr_scale >= 0) || !std::isfinite(o.surface_lr_scale))
    throw InputError(what + ": surface_lr_scale must be >= 0");
  o.intrinsic = 0;  // later addition: absent = L_6D
  if (j.contains("intrinsic")) field(j, "", "intrinsic", o.intrinsic);
  if (!(o.intrinsic >= 0) || !std::isfinite(o.intrinsic))
    throw InputError(what + ": intrinsic must be >= 0");
  o.intrinsic_until = 1;  // later addition: absent = the whole run
  if (j.contains("intrinsic_until")) field(j, "", "intrinsic_until", o.intrinsic_until);
  if (!(o.intrinsic_until >= 0 && o.intrinsic_until <= 1))
    throw InputError(what + ": intrinsic_until must be in [0, 1]");
  o.spectral_map = 0;  // later addition: absent = off
  if (j.contains("spectral_map")) field(j, "", "spectral_map", o.spectral_map);
  if (!(o.spectral_map >= 0) || !std::isfinite(o.spectral_map))
    throw InputError(what + ": spectral_map must be >= 0");
  o.spectral_map_until = 0.5;  // later addition
  if (j.contains("spectral_map_until")) field(j, "", "spectral_map_until", o.spectral_map_until);
  if (!(o.spectral_map_until > 0 && o.spectral_map_until <= 1))
    throw InputError(what + ": spectral_map_until must be in (0, 1]");
  o.template_coverage = false;  // later addition: absent = the medoid
  if (j.contains("template_coverage")) field(j, "", "template_coverage", o.template_coverage);
  o.register_nodes = false;  // later additions: absent = nodes from zero, no prior
  if (j.contains("register_nodes")) field(j, "", "register_nodes", o.register_nodes);
  o.register_prior = 0;
  if (j.contains("register_prior")) field(j, "", "register_prior", o.register_prior);
  if (!(o.register_prior >= 0) || !std::isfinite(o.register_prior))
    throw InputError(what + ": register_prior must be >= 0");
  o.auto_register = 0;  // later addition: absent = never
  if (j.contains("auto_register")) field(j, "", "auto_register", o.auto_register);
  if (!(o.auto_register >= 0) || !std::isfinite(o.auto_register))
    throw InputError(what + ": auto_register must be >= 0");
  o.nodes_lr_scale = 1;  // later addition: absent = one rate
  if (j.contains("nodes_lr_scale")) field(j, "", "nodes_lr_scale", o.nodes_lr_scale);
  if (!(o.nodes_lr_scale >= 0) || !std::isfinite(o.nodes_lr_scale))
    throw InputError(what + ": nodes_lr_scale must be >= 0");
  o.nodes_width = 1;  // later addition: absent = the width before the default became 2
  if (j.contains("nodes_width")) field(j, "", "nodes_width", o.nodes_width);
  if (!(o.nodes_width > 0) || !std::isfinite(o.nodes_width))
    throw InputError(what + ": nodes_width must be positive");
  o.fine_width = 1;  // later addition: absent = the default (used only with atlas.fine_nodes)
  if (j.contains("fine_width")) field(j, "", "fine_width", o.fine_width);
  if (!(o.fine_width > 0) || !std::isfinite(o.fine_width))
    throw InputError(what + ": fine_width must be positive");
  o.parallel_shapes = false;  // later addition: runs before it took one shape at a time
  if (j.contains("parallel_shapes")) field(j, "", "parallel_shapes", o.parallel_shapes);
  o.metric_end = -1;  // later addition: absent = a constant lambda_metric
  if (j.contains("metric_end")) field(j, "", "metric_end", o.metric_end);
  if (!std::isfinite(o.metric_end)) throw InputError(what + ": metric_end must be finite");
  o.metric_until = -1;  // later addition: absent = the first learning-rate decay
  if (j.contains("metric_until")) field(j, "", "metric_until", o.metric_until);
  if (!(o.metric_until < 0 || (o.metric_until > 0 && o.metric_until <= 1)))
    throw InputError(what + ": metric_until must be in (0, 1] or < 0");
  o.template_shape = 0;  // later addition: absent = shape 0, what older runs used
  if (j.contains("template_shape")) field(j, "", "template_shape", o.template_shape);
  o.metric_conformal = false;  // later addition: absent = the isometric L_metric
  if (j.contains("metric_conformal")) field(j, "", "metric_conformal", o.metric_conformal);
  o.chart_from = 0;
  if (j.contains("chart_from")) field(j, "", "chart_from", o.chart_from);
  if (!(o.chart_from >= 0 && o.chart_from <= 1))
    throw InputError(what + ": chart_from must be in [0, 1]");
  o.evenness_from = 0;  // later addition: absent = all along
  if (j.contains("evenness_from")) field(j, "", "evenness_from", o.evenness_from);
  if (!(o.evenness_from >= 0 && o.evenness_from <= 1))
    throw InputError(what + ": evenness_from must be in [0, 1]");
  o.transport_from = 0.5;  // later addition: absent = off (weights.transport 0)
  if (j.contains("transport_from")) field(j, "", "transport_from", o.transport_from);
  if (!(o.transport_from >= 0 && o.transport_from <= 1))
    throw InputError(what + ": transport_from must be in [0, 1]");
  o.transport_points = 256;
  if (j.contains("transport_points")) field(j, "", "transport_points", o.transport_points);
  if (o.transport_points < 1) throw InputError(what + ": transport_points must be >= 1");
  o.template_max_steps = 0;  // later addition: absent = no cap
  if (j.contains("template_max_steps")) field(j, "", "template_max_steps", o.template_max_steps);
  if (o.template_max_steps < 0) throw InputError(what + ": template_max_steps must be >= 0");
  if (o.template_steps < -1 || !(o.template_share >= 0 && o.template_share < 1))
    throw InputError(what + ": template_steps must be >= -1 and template_share in [0, 1)");
  field(j, "", "pool", o.pool);
  field(j, "", "threads", o.threads);
  o.gemm = Gemm::eigen;  // later addition: absent = Eigen, the only backend before it
  if (j.contains("gemm")) {
    std::string name;
    field(j, "", "gemm", name);
    if (!parse_gemm(name, &o.gemm))
      throw InputError(what + ": field 'gemm' must be \"eigen\" or \"blas\"");
  }
  if (o.atlas.gaussians <= 0 || o.atlas.width <= 0 || o.atlas.chart_width < 0 ||
      o.atlas.hidden_layers < 0 || o.points <= 0 || o.atlas.shapes <= 0 || o.atlas.code_size <= 0 ||
      o.pool <= 0 || o.threads < 0 || o.orient_every < 0 || o.batch_shapes < 0 ||
      o.wrap_steps < 0 || o.reseed_every < 0 || o.atlas.code_layer < 0 || o.atlas.code_layer > 1 ||
      !(o.lr > 0) || !(o.atlas.softplus_beta >= 0) || !std::isfinite(o.atlas.softplus_beta) ||
      !std::isfinite(o.lr) || o.max_faults < 0 ||
      !(o.fault_lr_factor > 0 && o.fault_lr_factor <= 1))
    throw InputError(what + ": sizes must be positive");
  // The same bounds as the command line's, so a crafted file cannot make the
  // atlas allocate without limit.
  if (o.atlas.gaussians > 1000000 || o.atlas.width > 4096 || o.atlas.chart_width > 4096 ||
      o.atlas.hidden_layers > 32 || o.atlas.code_size > 4096 || o.atlas.shapes > 100000 ||
      o.points > 1000000 || o.pool > 10000000 || o.threads > 1024 || o.wrap_steps > 1000000)
    throw InputError(what + ": a size is beyond the command line's limits (corrupt settings?)");
  return o;
}

}  // namespace jsa
