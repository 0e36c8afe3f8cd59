#include "handcentric/props/checks/profile.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <sstream>

#include "check_runner.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/props/prefetch.hpp"
#include "handcentric/props/checks/distribution.hpp"
#include "handcentric/props/tolerance.hpp"

namespace handcentric::props {
namespace {

// The chunk's scale is floored here (1 mm, 1 mrad): a hand at rest has no size of its own.
constexpr double kScaleFloor = 1e-3;
constexpr int kMaxProfileScenes = 10'000;
constexpr int kMaxProfileSamples = 10'000;

void require_options(const ProfileOptions& options, Group group) {
  if (options.scenes < 1 || options.scenes > kMaxProfileScenes)
    throw InvalidArgument("profile: scenes " + std::to_string(options.scenes) +
                          " is out of range; use 1 to " + std::to_string(kMaxProfileScenes));
  if (options.samples < 2 || options.samples > kMaxProfileSamples)
    throw InvalidArgument("profile: samples " + std::to_string(options.samples) +
                          " is out of range; use 2 to " + std::to_string(kMaxProfileSamples));
  if (!(options.slope_step > 0.0 && options.slope_step <= 0.1))
    throw InvalidArgument("profile: slope_step " + std::to_string(options.slope_step) +
                          " is out of range; use a step in (0, 0.1]");
  for (double size : options.sizes) {
    if (!std::isfinite(size) || size <= 0.0 || size > 1e3) {
      std::ostringstream s;
      s << "profile: size " << size << " (" << profile_unit(group)
        << ") is out of range; use sizes in (0, 1000]";
      throw InvalidArgument(s.str());
    }
  }
  if (!options.centre.allFinite())
    throw InvalidArgument("profile: the centre has a non-finite coordinate; give a world point");
  if (options.shape.workspace)
    throw InvalidArgument(
        "profile: a workspace was given, but a profile draws g by its size alone; leave the "
        "workspace out");
}

Eigen::Vector3d unit_vector(std::mt19937_64& rng, bool in_plane) {
  for (;;) {
    Eigen::Vector3d v(standard_normal(rng), standard_normal(rng),
                      in_plane ? 0.0 : standard_normal(rng));
    if (v.norm() > 1e-6) return v.normalized();
  }
}

RigidTransform profile_transform_about_origin(Group group, double size, const Eigen::Vector3d& axis,
                                              const Eigen::Vector3d& direction) {
  const Eigen::Vector3d in_plane(direction.x(), direction.y(), 0.0);
  const Eigen::Vector3d planar =
      in_plane.norm() > 1e-12 ? in_plane.normalized() : Eigen::Vector3d::UnitX();
  switch (group) {
    case Group::translation:
      return RigidTransform(Rotation::identity(), size * direction);
    case Group::rotation:
      return RigidTransform(Rotation::exp(size * axis), Eigen::Vector3d::Zero());
    case Group::se2:
      return RigidTransform(Rotation::about_z(size), size * planar);
    case Group::se3:
      return RigidTransform(Rotation::exp(size * axis), size * direction);
    case Group::c8:
      return RigidTransform(Rotation::about_z(size), Eigen::Vector3d::Zero());
  }
  throw InvalidArgument("profile_transform: unknown group");
}

Spread spread_of(std::vector<double> values) {
  Spread out;
  if (values.empty()) return out;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  out.median = n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
  out.max = values.back();
  return out;
}

// One map under profile, whatever it is: D at g (the audit's pointwise error), the scale c, the
// slope's difference at +-h, and, when it has noise, the two sides as functions of eps.
struct ProfiledMap {
  std::function<double(const Scene&, const RigidTransform&)> error;
  std::function<double(const Scene&)> scale;
  std::function<double(const Scene&, const RigidTransform&, const RigidTransform&)> slope;
  /// Left and right side at g, as functions of eps; null for a deterministic map.
  std::function<detail::NoisePair(const Scene&, const RigidTransform&)> noise_pair;
};

struct LawDistance {
  double value = 0.0;
  bool exact = false;
};

std::vector<Eigen::VectorXd> normal_draws(Eigen::Index n, int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<Eigen::VectorXd> draws;
  for (int i = 0; i < count; ++i) {
    Eigen::VectorXd eps(n);
    for (Eigen::Index j = 0; j < n; ++j) eps(j) = standard_normal(rng);
    draws.push_back(std::move(eps));
  }
  return draws;
}

Eigen::MatrixXd sample_rows(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f,
                            const std::vector<Eigen::VectorXd>& draws, const std::string& name) {
  ask_ahead([&] { return draws; }, f);
  Eigen::MatrixXd rows;
  for (std::size_t i = 0; i < draws.size(); ++i) {
    const Eigen::VectorXd y = f(draws[i]);
    if (i == 0) rows.resize(static_cast<Eigen::Index>(draws.size()), y.size());
    if (y.size() != rows.cols())
      throw InvalidArgument("profile: " + name + " changed length between noise draws (" +
                            std::to_string(rows.cols()) + ", then " + std::to_string(y.size()) +
                            "); a map's output length depends on the scene alone");
    rows.row(static_cast<Eigen::Index>(i)) = y.transpose();
  }
  return rows;
}

// The distance between the two laws of `pair` (see the top of profile.hpp), not yet divided by c.
LawDistance law_distance(const detail::NoisePair& pair, double tolerance, std::uint64_t seed,
                         int samples) {
  const auto before = affine_law(pair.before, pair.noise_dimension, tolerance, seed);
  const auto after =
      before ? affine_law(pair.after, pair.noise_dimension, tolerance, seed) : std::nullopt;
  if (before && after) {
    // The covariance's difference as the change of the largest standard deviation s it implies
    // to first order ((s + delta)^2 - s^2 = 2 s delta): in the output's units, like the mean's,
    // without the square root that would turn rounding of 1e-17 into 3e-9.
    const LawDifference d = law_difference(*before, *after);
    const double largest_variance =
        std::max((before->noise_map * before->noise_map.transpose()).lpNorm<Eigen::Infinity>(),
                 (after->noise_map * after->noise_map.transpose()).lpNorm<Eigen::Infinity>());
    const double spread =
        largest_variance > 0.0 ? d.covariance / (2.0 * std::sqrt(largest_variance)) : d.covariance;
    return {std::max(d.mean, spread), true};
  }
  const std::vector<Eigen::VectorXd> draws = normal_draws(pair.noise_dimension, samples, seed + 1);
  const Eigen::MatrixXd x = sample_rows(pair.before, draws, pair.name);
  const Eigen::MatrixXd y = sample_rows(pair.after, draws, pair.name);
  if (x.cols() != y.cols()) return {std::numeric_limits<double>::infinity(), false};
  return {std::max(0.0, energy_distance(x, y)), false};
}

// The energy distance between two independent samples of the left side at g = I.
double sampling_floor(const detail::NoisePair& pair, std::uint64_t seed, int samples) {
  const Eigen::MatrixXd x =
      sample_rows(pair.before, normal_draws(pair.noise_dimension, samples, seed + 1), pair.name);
  const Eigen::MatrixXd y =
      sample_rows(pair.before, normal_draws(pair.noise_dimension, samples, seed + 2), pair.name);
  return std::max(0.0, energy_distance(x, y));
}

struct SceneRow {
  std::vector<double> pointwise, distribution;
  std::vector<bool> exact;
  double slope = 0.0;
  std::optional<double> floor;
};

SceneRow profile_scene(const ProfiledMap& map, const ProfileCase& c, Group group,
                       const std::vector<double>& sizes, const ProfileOptions& options,
                       std::uint64_t scene_seed) {
  SceneRow row;
  const double scale = std::max(map.scale(c.scene), kScaleFloor);
  const double h = options.slope_step;
  // For c8 the slope is taken along the rotation about z, the continuous group C8 sits in.
  const RigidTransform plus = profile_transform(group, h, c.axis, c.direction, options.centre);
  const RigidTransform minus = profile_transform(group, -h, c.axis, c.direction, options.centre);
  row.slope = map.slope(c.scene, plus, minus) / (2.0 * h * scale);
  for (double size : sizes) {
    const RigidTransform g = profile_transform(group, size, c.axis, c.direction, options.centre);
    row.pointwise.push_back(map.error(c.scene, g) / scale);
    if (!map.noise_pair) continue;
    const double tolerance = pointwise_tolerance(c.scene, g * c.scene);
    const LawDistance d =
        law_distance(map.noise_pair(c.scene, g), tolerance, scene_seed, options.samples);
    row.distribution.push_back(d.value / scale);
    row.exact.push_back(d.exact);
    if (!d.exact && !row.floor)
      row.floor = sampling_floor(map.noise_pair(c.scene, RigidTransform::identity()), scene_seed,
                                 options.samples) /
                  scale;
  }
  return row;
}

Profile run_profile(const ProfiledMap& map, const std::string& name, Component component,
                    Group group, const ProfileOptions& options) {
  require_options(options, group);
  const std::vector<double> sizes =
      options.sizes.empty() ? default_profile_sizes(group) : options.sizes;
  const std::vector<ProfileCase> cases = profile_cases(options);
  const auto scene_seed = [&](std::size_t i) {
    return options.noise_seed * 1000003ULL + static_cast<std::uint64_t>(i);
  };
  const auto row = [&](std::size_t i) {
    return profile_scene(map, cases[i], group, sizes, options, scene_seed(i));
  };
  detail::answer_units_ahead(options.prefetch, cases.size(), [&](std::size_t i) { (void)row(i); });
  std::vector<SceneRow> rows;
  for (std::size_t i = 0; i < cases.size(); ++i) rows.push_back(row(i));

  Profile profile;
  profile.name = name;
  profile.component = component;
  profile.group = group;
  profile.view = view_of(options.shape);
  profile.scenes = options.scenes;
  profile.seed = options.seed;
  profile.slope_step = options.slope_step;
  profile.centre = options.centre;
  std::vector<double> slopes, floors;
  bool any_exact = false, any_energy = false;
  for (const SceneRow& r : rows) {
    slopes.push_back(r.slope);
    if (r.floor) floors.push_back(*r.floor);
    for (bool e : r.exact) (e ? any_exact : any_energy) = true;
  }
  profile.slope = spread_of(slopes);
  for (std::size_t k = 0; k < sizes.size(); ++k) {
    ProfilePoint point;
    point.size = sizes[k];
    point.in_group = profile_size_in_group(group, sizes[k]);
    std::vector<double> pointwise, distribution;
    for (const SceneRow& r : rows) {
      pointwise.push_back(r.pointwise[k]);
      if (map.noise_pair) distribution.push_back(r.distribution[k]);
    }
    point.pointwise = spread_of(pointwise);
    if (map.noise_pair) point.distribution = spread_of(distribution);
    profile.points.push_back(point);
  }
  if (map.noise_pair) {
    profile.distribution_method = any_exact && any_energy ? "exact_gaussian and energy_distance"
                                  : any_exact             ? "exact_gaussian"
                                                          : "energy_distance";
    if (!floors.empty()) profile.distribution_floor = spread_of(floors).median;
  }
  return profile;
}

ProfiledMap function_map(const SceneFunction& f) {
  ProfiledMap map;
  map.error = [f](const Scene& s, const RigidTransform& g) {
    return detail::inf_distance(f(g * s), f(s));
  };
  map.scale = [f](const Scene& s) {
    const Eigen::VectorXd v = f(s);
    return v.size() == 0 ? 0.0 : v.lpNorm<Eigen::Infinity>();
  };
  map.slope = [f](const Scene& s, const RigidTransform& plus, const RigidTransform& minus) {
    return detail::inf_distance(f(plus * s), f(minus * s));
  };
  return map;
}

}  // namespace

ProfileOptions with_audit_setup(ProfileOptions options, const ClassifierOptions& classifier,
                                View view) {
  const CheckOptions check = with_view(classifier.check, view);
  options.shape = check.shape;
  options.prefetch = check.prefetch;
  options.seed = check.seed;
  options.noise_seed = check.noise_seed;
  return options;
}

std::vector<ProfileCase> profile_cases(const ProfileOptions& options) {
  require_options(options, Group::se3);
  std::vector<Scene> scenes;
  detail::run_silently([&] { scenes.push_back(*scene(options.shape)); }, "profile scenes",
                       options.seed, options.scenes);
  std::mt19937_64 rng(options.seed ^ 0x9e3779b97f4a7c15ULL);
  std::vector<ProfileCase> cases;
  for (Scene& s : scenes) {
    const Eigen::Vector3d axis =
        options.shape.planar ? Eigen::Vector3d::UnitZ() : unit_vector(rng, false);
    const Eigen::Vector3d direction = unit_vector(rng, options.shape.planar);
    cases.push_back({std::move(s), axis, direction});
  }
  return cases;
}

RigidTransform profile_transform(Group group, double size, const Eigen::Vector3d& axis,
                                 const Eigen::Vector3d& direction, const Eigen::Vector3d& centre) {
  const RigidTransform about_origin = profile_transform_about_origin(group, size, axis, direction);
  const Eigen::Matrix3d& R = about_origin.rotation().matrix();
  return RigidTransform(about_origin.rotation(), about_origin.translation() + centre - R * centre);
}

std::string profile_unit(Group group) {
  switch (group) {
    case Group::translation:
      return "m";
    case Group::rotation:
    case Group::c8:
      return "rad";
    case Group::se2:
    case Group::se3:
      return "rad and m";
  }
  return "";
}

std::vector<double> default_profile_sizes(Group group) {
  if (group == Group::c8) {
    std::vector<double> sizes;
    for (int k = 1; k <= 16; ++k) sizes.push_back(k * std::numbers::pi / 8.0);
    return sizes;
  }
  std::vector<double> sizes = {1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.3, 1.0};
  if (group == Group::translation) {
    sizes.push_back(3.0);
    sizes.push_back(10.0);
  } else {
    sizes.push_back(2.0);
    sizes.push_back(3.0);
  }
  return sizes;
}

bool profile_size_in_group(Group group, double size) {
  if (group != Group::c8) return true;
  const double steps = size / (std::numbers::pi / 4.0);
  return std::abs(steps - std::round(steps)) * (std::numbers::pi / 4.0) < 1e-9;
}

Profile profile_function(const SceneFunction& f, const std::string& name, Component component,
                         Group group, const ProfileOptions& options) {
  if (!f) throw InvalidArgument("profile_function: no function given");
  return run_profile(function_map(f), name, component, group, options);
}

Profile profile_flow(std::shared_ptr<const FlowTarget> target, Component component, Group group,
                     const ProfileOptions& options) {
  if (!target) throw InvalidArgument("profile_flow: no flow target given (null)");
  if (component != Component::flow_input && component != Component::flow_target)
    throw InvalidArgument("profile_flow: component '" + to_string(component) +
                          "' is not a flow's; use flow_input or flow_target");
  const bool input = component == Component::flow_input;
  const SceneFunction f = input ? flow_input_of(target, options.noise_seed, options.flow_time)
                                : flow_target_of(target, options.noise_seed, options.flow_time);
  ProfiledMap map = function_map(f);
  const double t = options.flow_time;
  map.noise_pair = [target, input, t](const Scene& s, const RigidTransform& g) {
    detail::NoisePair pair;
    pair.noise_dimension = target->noise_dimension(s);
    pair.name = target->name();
    const Scene moved = g * s;
    pair.before = [target, input, s, t](const Eigen::VectorXd& eps) {
      FlowSample sample = (*target)(s, eps, t);
      return input ? sample.input : sample.target;
    };
    pair.after = [target, input, moved, t](const Eigen::VectorXd& eps) {
      FlowSample sample = (*target)(moved, eps, t);
      return input ? sample.input : sample.target;
    };
    return pair;
  };
  return run_profile(map, target->name(), component, group, options);
}

Profile profile_policy(const NoisyPolicy& policy, Group group, const ProfileOptions& options) {
  const Eigen::VectorXd noise = fixed_noise(policy.noise_dimension(), options.noise_seed);
  const NoisyPolicy* p = &policy;
  ProfiledMap map;
  map.error = [p, noise](const Scene& o, const RigidTransform& g) {  // eq. (4)
    return detail::chunk_distance(detail::moved_by(g, detail::checked_act(*p, o, noise)),
                                  detail::checked_act(*p, g * o, noise));
  };
  map.scale = [p, noise](const Scene& o) {
    double reach = 0.0;
    for (const RigidTransform& world_T_handk : detail::checked_act(*p, o, noise))
      reach = std::max(reach, distance(world_T_handk, o.world_T_hand0()));
    return reach;
  };
  map.slope = [p, noise](const Scene& o, const RigidTransform& plus, const RigidTransform& minus) {
    // exp(-tX) a(exp(tX) o, n) at t = +-h: the policy pulled back, whose derivative is L_X a.
    return detail::chunk_distance(
        detail::moved_by(plus.inverse(), detail::checked_act(*p, plus * o, noise)),
        detail::moved_by(minus.inverse(), detail::checked_act(*p, minus * o, noise)));
  };
  map.noise_pair = [p](const Scene& o, const RigidTransform& g) {
    detail::NoisePair pair;
    pair.noise_dimension = p->noise_dimension();
    pair.name = p->name();
    const Scene moved = g * o;
    pair.before = [p, o, g](const Eigen::VectorXd& n) {
      return detail::flatten_affine(detail::moved_by(g, detail::checked_act(*p, o, n)));
    };
    pair.after = [p, moved](const Eigen::VectorXd& n) {
      return detail::flatten_affine(detail::checked_act(*p, moved, n));
    };
    return pair;
  };
  return run_profile(map, policy.name(), Component::policy, group, options);
}

std::string profile_json(const std::vector<Profile>& profiles) {
  nlohmann::json out;
  out["normalization"] =
      "each error is divided by the chunk's scale c: a component's max(|f(s)|_inf, 1e-3), a "
      "policy's max(max_k d(a(o,n)_k, T_0), 1e-3) with d(A, B) = |R_A - R_B|_F + |p_A - p_B|_2 "
      "(docs/AUDIT.md, Profiles)";
  nlohmann::json list = nlohmann::json::array();
  for (const Profile& p : profiles) {
    nlohmann::json j;
    j["name"] = p.name;
    j["component"] = to_string(p.component);
    j["group"] = to_string(p.group);
    j["view"] = to_string(p.view);
    j["unit"] = profile_unit(p.group);
    j["scenes"] = p.scenes;
    j["seed"] = p.seed;
    j["centre"] = {p.centre.x(), p.centre.y(), p.centre.z()};
    nlohmann::json sizes = nlohmann::json::array(), in_group = nlohmann::json::array(),
                   pw_median = nlohmann::json::array(), pw_max = nlohmann::json::array(),
                   d_median = nlohmann::json::array(), d_max = nlohmann::json::array();
    for (const ProfilePoint& point : p.points) {
      sizes.push_back(point.size);
      in_group.push_back(point.in_group);
      pw_median.push_back(point.pointwise.median);
      pw_max.push_back(point.pointwise.max);
      if (point.distribution) {
        d_median.push_back(point.distribution->median);
        d_max.push_back(point.distribution->max);
      }
    }
    j["sizes"] = sizes;
    j["in_group"] = in_group;
    j["pointwise"] = {{"median", pw_median}, {"max", pw_max}};
    if (p.distribution_method.empty()) {
      j["distribution"] = nullptr;
    } else {
      j["distribution"] = {{"method", p.distribution_method}, {"median", d_median}, {"max", d_max}};
      j["distribution"]["floor"] =
          p.distribution_floor ? nlohmann::json(*p.distribution_floor) : nlohmann::json(nullptr);
    }
    j["lie_derivative"] = {
        {"median", p.slope.median},
        {"max", p.slope.max},
        {"step", p.slope_step},
        {"method",
         "central difference at +-step along the scene's unit generator, divided by "
         "2 step c (Gruver et al. 2023)"}};
    list.push_back(j);
  }
  out["profiles"] = list;
  return out.dump(2) + "\n";
}

}  // namespace handcentric::props
