#include "handcentric/props/observation/generators.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <type_traits>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/props/observation/recorded.hpp"

namespace handcentric::props {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr int kResolution = 1 << 30;  // uniform numbers are k / 2^30, k an integer (shrinks to 0)

// A uniform number in [0, 1).
rc::Gen<double> unit_interval() {
  return rc::gen::map(uniform_integer(0, kResolution),
                      [](int k) { return static_cast<double>(k) / kResolution; });
}

// A uniform number in [-max_abs, max_abs] that shrinks toward 0 (RapidCheck shrinks an integer
// toward the low end of its range, which would be -max_abs: a half turn for an angle). The
// integer k in [0, 2^31] is taken to 0, 1, -1, 2, -2, ..., 2^30, -2^30, one value each, so the
// law is the uniform one on the grid and a smaller k is a smaller |value|.
rc::Gen<double> symmetric(double max_abs) {
  return rc::gen::map(uniform_integer<std::int64_t>(0, 2 * std::int64_t{kResolution} + 1),
                      [max_abs](std::int64_t k) {
                        const std::int64_t signed_k = k % 2 == 1 ? (k + 1) / 2 : -(k / 2);
                        return max_abs * static_cast<double>(signed_k) / kResolution;
                      });
}

// A Haar-uniform unit axis (the axis of a Haar rotation is uniform on the sphere).
rc::Gen<Eigen::Vector3d> unit_axis() {
  return rc::gen::map(rc::gen::tuple(unit_interval(), unit_interval()), [](const auto& uv) {
    return sphere_point(std::get<0>(uv), std::get<1>(uv));
  });
}

// A rotation by `angle` (drawn by angle_gen) about a uniform axis.
rc::Gen<Rotation> axis_angle(rc::Gen<double> angle_gen) {
  return rc::gen::map(rc::gen::tuple(unit_axis(), angle_gen), [](const auto& axis_angle) {
    return Rotation::exp(std::get<1>(axis_angle) * std::get<0>(axis_angle));
  });
}

rc::Gen<Rotation> rotation_about_z() {
  return rc::gen::map(symmetric(kPi), [](double angle) { return Rotation::about_z(angle); });
}

rc::Gen<Rotation> z_rotation_edge_cases() {
  return rc::gen::element(Rotation::identity(), Rotation::about_z(1e-12),
                          Rotation::about_z(kPi - 1e-9), Rotation::about_z(kPi));
}

rc::Gen<Rotation> c8_rotation() {
  return rc::gen::map(uniform_integer(0, 8),
                      [](int i) { return Rotation::about_z(i * kPi / 4.0); });
}

// A length drawn log-uniformly in [kSmallestLength, kLargestLength] (shrinks to the smallest):
// a leak proportional to a position is then seen at every scale, not only at 10 m, where the
// tolerance's (1 + L) is largest.
constexpr double kSmallestLength = 0.01, kLargestLength = 10.0;

rc::Gen<double> log_uniform_length() {
  return rc::gen::map(unit_interval(), [](double u) {
    return kSmallestLength * std::pow(kLargestLength / kSmallestLength, u);
  });
}

// A vector of log-uniform length in a uniform direction (in the plane z = 0 when planar).
rc::Gen<Eigen::Vector3d> log_uniform_vector(bool planar) {
  if (planar) {
    return rc::gen::map(rc::gen::tuple(log_uniform_length(), unit_interval()), [](const auto& la) {
      const double angle = 2.0 * kPi * std::get<1>(la);
      return Eigen::Vector3d(std::get<0>(la) * std::cos(angle), std::get<0>(la) * std::sin(angle),
                             0.0);
    });
  }
  return rc::gen::map(rc::gen::tuple(log_uniform_length(), unit_axis()), [](const auto& la) {
    return Eigen::Vector3d(std::get<0>(la) * std::get<1>(la));
  });
}

rc::Gen<Eigen::Vector3d> translation_with_edges(bool planar) {
  auto gen = rc::gen::weightedOneOf<Eigen::Vector3d>({
      {8, log_uniform_vector(planar)},
      {1, rc::gen::just<Eigen::Vector3d>(Eigen::Vector3d::Zero())},
      {1, rc::gen::map(unit_axis(),
                       [](const Eigen::Vector3d& axis) -> Eigen::Vector3d { return 1e3 * axis; })},
  });
  if (!planar) return gen;
  return rc::gen::map(gen, [](Eigen::Vector3d p) {
    p.z() = 0.0;
    return p;
  });
}

rc::Gen<RigidTransform> combine(rc::Gen<Rotation> rotations,
                                rc::Gen<Eigen::Vector3d> translations) {
  return rc::gen::map(rc::gen::tuple(rotations, translations), [](const auto& rp) {
    return RigidTransform(std::get<0>(rp), std::get<1>(rp));
  });
}

// A twist for one control step: translations up to `step`, rotation angles up to `turn`.
rc::Gen<Twist> step_twist(double step, double turn) {
  return rc::gen::map(rc::gen::tuple(translation(step), translation(turn)), [](const auto& vw) {
    Twist twist;
    twist << std::get<0>(vw), std::get<1>(vw);
    return twist;
  });
}

// A step twist in the plane: translation in x, y and rotation about z only.
rc::Gen<Twist> planar_step_twist(double step, double turn) {
  return rc::gen::map(rc::gen::tuple(translation(step), symmetric(turn)), [](const auto& vw) {
    Twist twist;
    const Eigen::Vector3d& v = std::get<0>(vw);
    twist << v.x(), v.y(), 0.0, 0.0, 0.0, std::get<1>(vw);
    return twist;
  });
}

// A step twist, or, one time in eight, none: a hand at rest, T_k = T_0 exactly, where a map
// that bins relative poses sits on the bin edge at 0 (a robot pausing in a demo does this).
rc::Gen<Twist> step_or_rest(double step, double turn, bool planar) {
  return rc::gen::weightedOneOf<Twist>(
      {{7, planar ? planar_step_twist(step, turn) : step_twist(step, turn)},
       {1, rc::gen::just<Twist>(Twist::Zero())}});
}

// A rotation about z: uniform angles mixed with the edge cases (identity, 1e-12, pi - 1e-9, pi).
rc::Gen<Rotation> planar_rotation() {
  return rc::gen::weightedOneOf<Rotation>({{4, rotation_about_z()}, {1, z_rotation_edge_cases()}});
}

// A uniform direction in the plane z = 0.
rc::Gen<Eigen::Vector3d> planar_axis() {
  return rc::gen::map(unit_interval(), [](double u) {
    return Eigen::Vector3d(std::cos(2.0 * kPi * u), std::sin(2.0 * kPi * u), 0.0);
  });
}

}  // namespace

rc::Gen<Rotation> haar_rotation() {
  // A uniform axis and an angle by the inverse CDF of Haar's angle law (haar_angle): exactly
  // Haar, and the number behind the angle shrinks to 0, the identity, so that a failure shrinks
  // to the smallest turn that still fails. (Shoemake's map of three uniform numbers is Haar
  // too, but maps their zeros to a half turn, where rotation vectors jump.)
  return axis_angle(rc::gen::map(unit_interval(), [](double u) { return haar_angle(u); }));
}

rc::Gen<Rotation> rotation_near_pi() {
  return axis_angle(rc::gen::map(unit_interval(), [](double u) { return kPi - 1e-10 * u; }));
}

rc::Gen<Rotation> rotation_near_identity() {
  return axis_angle(rc::gen::map(unit_interval(), [](double u) { return 1e-10 * u; }));
}

rc::Gen<Rotation> rotation() {
  return rc::gen::weightedOneOf<Rotation>({
      {16, haar_rotation()},
      {1, rc::gen::just(Rotation::identity())},
      {1, axis_angle(rc::gen::just(1e-12))},
      {1, axis_angle(rc::gen::just(kPi - 1e-9))},
      {1, axis_angle(rc::gen::just(kPi))},
  });
}

rc::Gen<Eigen::Vector3d> translation(double max_abs) {
  return rc::gen::map(rc::gen::tuple(symmetric(max_abs), symmetric(max_abs), symmetric(max_abs)),
                      [](const auto& xyz) {
                        return Eigen::Vector3d(std::get<0>(xyz), std::get<1>(xyz),
                                               std::get<2>(xyz));
                      });
}

rc::Gen<RigidTransform> group_element(Group group, bool planar) {
  switch (group) {
    case Group::translation:
      return combine(rc::gen::just(Rotation::identity()), translation_with_edges(planar));
    case Group::rotation:
      return combine(rotation(), rc::gen::just<Eigen::Vector3d>(Eigen::Vector3d::Zero()));
    case Group::se2:
      return combine(planar_rotation(), translation_with_edges(true));
    case Group::se3:
      return combine(rotation(), translation_with_edges(false));
    case Group::c8:
      return combine(c8_rotation(), rc::gen::just<Eigen::Vector3d>(Eigen::Vector3d::Zero()));
  }
  return rc::gen::just(RigidTransform::identity());
}

namespace {

// A point with coordinates in [-max_abs, max_abs], in the plane z = 0 when planar.
rc::Gen<Eigen::Vector3d> point(double max_abs, bool planar) {
  if (!planar) return translation(max_abs);
  return rc::gen::map(translation(max_abs), [](Eigen::Vector3d p) {
    p.z() = 0.0;
    return p;
  });
}

// Between min_count and max_count points, the count uniform.
rc::Gen<std::vector<Eigen::Vector3d>> points(int min_count, int max_count, double max_abs,
                                             bool planar) {
  return rc::gen::mapcat(
      uniform_integer(std::max(min_count, 0), std::max(min_count, max_count) + 1),
      [max_abs, planar](int count) {
        return rc::gen::container<std::vector<Eigen::Vector3d>>(static_cast<std::size_t>(count),
                                                                point(max_abs, planar));
      });
}

}  // namespace

rc::Gen<Scene> scene(SceneShape shape) {
  // One length scale per scene, log-uniform in [1 cm, 10 m]: the start pose is that far out, and
  // steps and points are drawn in proportion (at 10 m: steps up to 0.1 m, hand points within
  // 1 m, world points within 10 m). Extra poses stay anywhere within 10 m.
  // The counts come first: RapidCheck shrinks a tuple's elements in order, and a witness reads
  // best with its chunk and history shortest, whatever the numbers shrink to after them.
  auto geometry = rc::gen::mapcat(log_uniform_length(), [shape](double scale) {
    return rc::gen::apply(
        [](int history, int chunk, const std::vector<Eigen::Vector3d>& hand_points,
           const std::vector<Eigen::Vector3d>& world_points, const Rotation& world_R_hand0,
           const Eigen::Vector3d& direction, double scale, const Twist& forward,
           const Twist& backward) {
          Scene s;
          const RigidTransform world_T_hand0(world_R_hand0, scale * direction);
          // Smooth, rotating motion: a constant body twist per control step, each way from T_0.
          const RigidTransform step_forward = RigidTransform::exp(forward);
          const RigidTransform step_backward = RigidTransform::exp(backward);
          s.world_T_hand_history.push_back(world_T_hand0);
          for (int h = 1; h <= history; ++h) {
            s.world_T_hand_history.push_back(s.world_T_hand_history.back() * step_backward);
          }
          RigidTransform world_T_handk = world_T_hand0;
          for (int k = 1; k <= chunk; ++k) {
            world_T_handk = world_T_handk * step_forward;
            s.world_T_hand_chunk.push_back(world_T_handk);
          }
          s.hand_points = hand_points;
          s.world_points = world_points;
          return s;
        },
        uniform_integer(shape.min_history, shape.max_history + 1),
        uniform_integer(shape.min_chunk, shape.max_chunk + 1),
        points(shape.min_hand_points, shape.max_hand_points, 0.1 * scale, shape.planar),
        points(shape.min_world_points, shape.max_world_points, scale, shape.planar),
        shape.planar ? planar_rotation() : rotation(), shape.planar ? planar_axis() : unit_axis(),
        rc::gen::just(scale), step_or_rest(0.01 * scale, 0.3, shape.planar),
        step_or_rest(0.01 * scale, 0.3, shape.planar));
  });
  if (shape.extra_pose_names.empty() && shape.scalar_names.empty()) return geometry;
  // Named extras: one random pose per name (anywhere within 10 m, any orientation; in the plane
  // and turned about z only when planar), one number per scalar.
  const auto poses = rc::gen::container<std::vector<RigidTransform>>(
      shape.extra_pose_names.size(), shape.planar ? combine(planar_rotation(), point(10.0, true))
                                                  : combine(rotation(), translation(10.0)));
  const auto numbers =
      rc::gen::container<std::vector<double>>(shape.scalar_names.size(), symmetric(1.0));
  return rc::gen::apply(
      [names = shape.extra_pose_names, scalar_names = shape.scalar_names](
          Scene s, const std::vector<RigidTransform>& world_T_extra,
          const std::vector<double>& values) {
        for (std::size_t i = 0; i < names.size(); ++i)
          s.extra_poses.emplace_back(names[i], world_T_extra[i]);
        for (std::size_t i = 0; i < scalar_names.size(); ++i)
          s.scalars.emplace_back(scalar_names[i], values[i]);
        return s;
      },
      geometry, poses, numbers);
}

namespace {

// Every world-frame position of a scene (Workspace::contains reads the same ones).
template <class Visit>
void for_each_world_position(Scene& scene, Visit visit) {
  for (RigidTransform& T : scene.world_T_hand_history) visit(T);
  for (RigidTransform& T : scene.world_T_hand_chunk) visit(T);
  for (Eigen::Vector3d& p : scene.world_points) visit(p);
  for (auto& [name, T] : scene.extra_poses) visit(T);
}

Eigen::Vector3d position_of(const RigidTransform& T) {
  return T.translation();
}
Eigen::Vector3d position_of(const Eigen::Vector3d& p) {
  return p;
}

// The scene scaled by k about `centre` and moved so that centre lands at `target`: a valid scene
// of the same shape and rotations (eye-in-hand points scaled too, so that it looks the same).
Scene scaled_and_placed(Scene scene, const Eigen::Vector3d& centre, double k,
                        const Eigen::Vector3d& target) {
  const auto place = [&](const Eigen::Vector3d& p) -> Eigen::Vector3d {
    return target + k * (p - centre);
  };
  for_each_world_position(scene, [&](auto& x) {
    if constexpr (std::is_same_v<std::decay_t<decltype(x)>, RigidTransform>) {
      x = RigidTransform(x.rotation(), place(x.translation()));
    } else {
      x = place(x);
    }
  });
  for (Eigen::Vector3d& p : scene.hand_points) p *= k;
  return scene;
}

// The translations t with R x + t inside the box for every world position x of `scene`, per
// axis [low, high] (non-empty by the placement's construction, up to rounding).
std::pair<Eigen::Vector3d, Eigen::Vector3d> feasible_translations(Scene scene,
                                                                  const Eigen::Matrix3d& R,
                                                                  const Workspace& box) {
  Eigen::Vector3d low = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  for_each_world_position(scene, [&](auto& x) {
    const Eigen::Vector3d turned = R * position_of(x);
    low = low.cwiseMax(box.min - turned);
    high = high.cwiseMin(box.max - turned);
  });
  return {low, high};
}

}  // namespace

rc::Gen<std::pair<Scene, RigidTransform>> case_in_workspace(const SceneShape& shape, Group group,
                                                            const Workspace& box) {
  SceneShape free_shape = shape;
  free_shape.workspace.reset();
  const Eigen::Vector3d half = 0.5 * (box.max - box.min);
  const Eigen::Vector3d middle = 0.5 * (box.max + box.min);
  // The room each group's rotations leave: a ball about the origin (rotation), a cylinder about
  // world z (c8), the box itself (groups with translations, which move the scene back in).
  const double room = box.room_for(group);
  const bool planar = shape.planar;
  if (planar && !(box.min.z() <= 0.0 && box.max.z() >= 0.0)) {
    throw InvalidArgument("the workspace " + box.describe() +
                          " does not contain the plane z = 0 of the 2D task's scenes: give a box "
                          "with z0 <= 0 <= z1");
  }
  return rc::gen::apply(
      [box, group, room, half, middle, planar](
          Scene scene, double size_u, const Eigen::Vector3d& spot, const RigidTransform& g_drawn,
          const Eigen::Vector3d& t_u) {
        // The scene's centre and radius (over its world positions).
        Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
        Eigen::Vector3d hi = -lo;
        for_each_world_position(scene, [&](auto& x) {
          lo = lo.cwiseMin(position_of(x));
          hi = hi.cwiseMax(position_of(x));
        });
        const Eigen::Vector3d centre = 0.5 * (lo + hi);
        double radius = 0.0;
        for_each_world_position(
            scene, [&](auto& x) { radius = std::max(radius, (position_of(x) - centre).norm()); });
        // Scaled to a radius between room / 20 and room / 2 (never up), leaving room to move.
        const double target_radius = room * (0.05 + 0.45 * size_u);
        const double k = radius > target_radius ? target_radius / radius : 1.0;
        const double r = k * radius;
        Eigen::Vector3d target;  // spot in [-1, 1]^3 picks where the centre goes
        if (group == Group::rotation) {
          target = (room - r) * spot / std::max(1.0, spot.norm());
        } else if (group == Group::c8) {
          Eigen::Vector2d xy = spot.head<2>() / std::max(1.0, spot.head<2>().norm());
          target << (room - r) * xy, middle.z() + (half.z() - r) * spot.z();
        } else {
          target = middle + (half - Eigen::Vector3d::Constant(r)).cwiseProduct(spot);
        }
        if (planar) target.z() = centre.z();  // the scene stays in its plane (z = 0)
        Scene placed = scaled_and_placed(std::move(scene), centre, k, target);
        const Eigen::Matrix3d R = g_drawn.rotation().matrix();
        Eigen::Vector3d t = Eigen::Vector3d::Zero();
        if (group == Group::translation || group == Group::se2 || group == Group::se3) {
          const auto [low, high] = feasible_translations(placed, R, box);
          const int axes = group == Group::se2 || planar ? 2 : 3;  // se2 moves in the plane
          for (int axis = 0; axis < axes; ++axis)
            t(axis) = low(axis) + t_u(axis) * std::max(0.0, high(axis) - low(axis));
        }
        return std::make_pair(std::move(placed), RigidTransform(g_drawn.rotation(), t));
      },
      scene(free_shape), unit_interval(), translation(1.0), group_element(group, planar),
      rc::gen::map(translation(1.0), [](const Eigen::Vector3d& u) {
        return Eigen::Vector3d(0.5 * (u.array() + 1.0));
      }));
}

namespace {

// g_drawn turned back toward the identity until a translation of `group` keeps g * scene inside
// the box (recorded_case); t_u in [0, 1]^3 picks that translation among the feasible ones.
RigidTransform kept_inside(const Scene& scene, const RigidTransform& g_drawn, Group group,
                           const Workspace& box, const Eigen::Vector3d& t_u, bool planar) {
  const bool translates = group == Group::translation || group == Group::se2 || group == Group::se3;
  const int axes = group == Group::se2 || planar ? 2 : 3;  // se2 moves in the plane
  // The rotations to try, the drawn one first: c8 one step of 45 degrees at a time toward the
  // identity, the others with their angle halved (30 halvings reach below 1e-9 rad).
  std::vector<Rotation> tries;
  if (group == Group::c8) {
    const Eigen::Matrix3d R = g_drawn.rotation().matrix();
    int k = static_cast<int>(std::lround(std::atan2(R(1, 0), R(0, 0)) / (kPi / 4)));
    for (; k != 0; k -= k > 0 ? 1 : -1)
      tries.push_back(Rotation::exp(Eigen::Vector3d(0.0, 0.0, k * kPi / 4)));
  } else {
    const Eigen::Vector3d w = g_drawn.rotation().log();
    for (int j = 0; j <= 30 && w.norm() > 0.0; ++j)
      tries.push_back(Rotation::exp(std::ldexp(1.0, -j) * w));
  }
  tries.push_back(Rotation());
  for (const Rotation& R : tries) {
    const auto [low, high] = feasible_translations(scene, R.matrix(), box);
    Eigen::Vector3d t = Eigen::Vector3d::Zero();
    bool fits = true;
    for (int axis = 0; axis < 3; ++axis) {
      if (translates && axis < axes) {
        fits = fits && low(axis) <= high(axis);
        t(axis) = low(axis) + t_u(axis) * std::max(0.0, high(axis) - low(axis));
      } else {
        fits = fits && low(axis) <= 0.0 && 0.0 <= high(axis);
      }
    }
    if (fits) return RigidTransform(R, t);
  }
  return RigidTransform::identity();  // the observation itself is inside (require_inside)
}

}  // namespace

rc::Gen<std::pair<Scene, RigidTransform>> recorded_case(const SceneShape& shape, Group group) {
  if (!shape.recorded) throw InvalidArgument("recorded_case needs recorded observations");
  std::shared_ptr<const RecordedObservations> data = shape.recorded;
  const bool eye_in_hand = shape.max_world_points == 0;
  const auto index = uniform_integer<std::size_t>(0, data->scenes.size());
  const auto observation = rc::gen::map(index, [data, eye_in_hand](std::size_t i) {
    Scene s = data->scenes[i];
    if (eye_in_hand) s.world_points.clear();
    return s;
  });
  if (!shape.workspace) {
    return rc::gen::apply(
        [](Scene s, const RigidTransform& g) { return std::make_pair(std::move(s), g); },
        observation, group_element(group, shape.planar));
  }
  const Workspace box = *shape.workspace;
  const bool planar = shape.planar;
  return rc::gen::apply(
      [box, group, planar](Scene s, const RigidTransform& g_drawn, const Eigen::Vector3d& t_u) {
        const RigidTransform g = kept_inside(s, g_drawn, group, box, t_u, planar);
        return std::make_pair(std::move(s), g);
      },
      observation, group_element(group, planar),
      rc::gen::map(translation(1.0), [](const Eigen::Vector3d& u) {
        return Eigen::Vector3d(0.5 * (u.array() + 1.0));
      }));
}

rc::Gen<Scene> shaped_scene(const SceneShape& shape) {
  // Translation leaves every scene shape room in any box, so the workspace's scenes are drawn so.
  const auto first = [](const std::pair<Scene, RigidTransform>& c) { return c.first; };
  if (shape.recorded) return rc::gen::map(recorded_case(shape, Group::translation), first);
  if (shape.workspace)
    return rc::gen::map(case_in_workspace(shape, Group::translation, *shape.workspace), first);
  return scene(shape);
}

}  // namespace handcentric::props
