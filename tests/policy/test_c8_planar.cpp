// The C8 baseline's planar encoding (c8_planar.hpp) and head c8ddpm: the action is a group
// action, it is the scene transform about the centre (with planted faults that the same check
// rejects), the encoding round-trips, the augmented data is C8-invariant, and the head trains
// on 8x the budget and refuses what it cannot encode.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "fixtures.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/policy/binary_io.hpp"
#include "handcentric/policy/c8_planar.hpp"
#include "handcentric/policy/head.hpp"
#include "handcentric/policy/trainer.hpp"
#include "throws.hpp"
#include "worst_error.hpp"  // tests/support

using namespace handcentric;
using namespace handcentric::policy;

namespace {

constexpr double kPi = std::numbers::pi;

double uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

RigidTransform random_planar_pose(std::mt19937_64& rng) {
  return RigidTransform::planar(uniform(rng, -kPi, kPi), uniform(rng, -50, 50),
                                uniform(rng, -50, 50));
}

// A planar scene: H = 2, K = 4, two eye-in-hand points and one world point (cm).
Scene planar_scene(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Scene scene;
  for (int h = 0; h < 3; ++h) scene.world_T_hand_history.push_back(random_planar_pose(rng));
  for (int k = 0; k < 4; ++k) scene.world_T_hand_chunk.push_back(random_planar_pose(rng));
  for (int i = 0; i < 2; ++i)
    scene.hand_points.emplace_back(uniform(rng, -5, 5), uniform(rng, -5, 5), 0.0);
  scene.world_points.emplace_back(uniform(rng, -50, 50), uniform(rng, -50, 50),
                                  uniform(rng, -1, 1));
  return scene;
}

const c8::Layout kActions{4, 0, 0};
const c8::Layout kObservations{3, 2, 1};

// C8's element k about `centre` as a world transform: c + R (x - c).
RigidTransform about(int k, const Eigen::Vector2d& centre) {
  const RigidTransform rotation = RigidTransform::planar(k * kPi / 4.0, 0.0, 0.0);
  return RigidTransform::planar(0.0, centre.x(), centre.y()) * rotation *
         RigidTransform::planar(0.0, -centre.x(), -centre.y());
}

using Act = std::function<Eigen::VectorXd(int, const Eigen::Vector2d&, const Eigen::VectorXd&,
                                          const c8::Layout&)>;

// The largest |encode(g scene) - act(k, encode(scene))| over scenes, elements and two centres,
// on actions and on observations: 0 up to round-off for the action of c8_planar.hpp.
double worst_scene_mismatch(const Act& act) {
  const AbsoluteRepresentation absolute;
  double worst = 0.0;
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    const Scene scene = planar_scene(seed);
    for (const Eigen::Vector2d& centre : {Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(3.0, -60.0)}) {
      for (int k = 1; k < 8; ++k) {
        const Scene moved = about(k, centre) * scene;
        const auto mismatch = [&](const Eigen::VectorXd& of_moved, const Eigen::VectorXd& of_scene,
                                  const c8::Layout& layout) {
          const Eigen::VectorXd expected = c8::encode_planar(of_moved, layout);
          return (expected - act(k, centre, c8::encode_planar(of_scene, layout), layout))
              .cwiseAbs()
              .maxCoeff<Eigen::PropagateNaN>();
        };
        worst = test::worst_of(worst, mismatch(absolute.encode_actions(moved),
                                               absolute.encode_actions(scene), kActions));
        worst = test::worst_of(worst, mismatch(absolute.encode_observation(moved),
                                               absolute.encode_observation(scene), kObservations));
      }
    }
  }
  return worst;
}

}  // namespace

TEST_CASE("c8_planar_action_is_the_scene_transform_about_the_centre", "[unit]") {
  CHECK(worst_scene_mismatch(c8::act_planar) < 1e-9);
}

TEST_CASE("c8_planar_scene_check_rejects_planted_faults", "[unit]") {
  // Positions rotated about the world origin instead of the centre: right only for centre 0.
  const Act about_origin = [](int k, const Eigen::Vector2d&, const Eigen::VectorXd& x,
                              const c8::Layout& layout) {
    return c8::act_planar(k, Eigen::Vector2d::Zero(), x, layout);
  };
  CHECK(worst_scene_mismatch(about_origin) > 1.0);
  // The heading left unrotated: positions move, (cos, sin) do not.
  const Act fixed_heading = [](int k, const Eigen::Vector2d& c, const Eigen::VectorXd& x,
                               const c8::Layout& layout) {
    Eigen::VectorXd out = c8::act_planar(k, c, x, layout);
    for (int i = 0; i < layout.poses; ++i)
      out.segment<2>(c8::kPlanarPoseSize * i + 3) = x.segment<2>(c8::kPlanarPoseSize * i + 3);
    return out;
  };
  CHECK(worst_scene_mismatch(fixed_heading) > 0.5);
  // Eye-in-hand points rotated like world points: the view is not invariant then.
  const Act turned_view = [](int k, const Eigen::Vector2d& c, const Eigen::VectorXd& x,
                             const c8::Layout& layout) {
    Eigen::VectorXd out = c8::act_planar(k, c, x, layout);
    const Eigen::Index hand = c8::kPlanarPoseSize * layout.poses;
    const Eigen::Rotation2D<double> R(k * kPi / 4.0);
    for (int i = 0; i < layout.hand_points; ++i)
      out.segment<2>(hand + 3 * i) = R * x.segment<2>(hand + 3 * i);
    return out;
  };
  CHECK(worst_scene_mismatch(turned_view) > 1e-2);
}

TEST_CASE("c8_planar_action_is_a_group_action", "[unit]") {
  std::mt19937_64 rng(7);
  const AbsoluteRepresentation absolute;
  for (std::uint64_t seed = 0; seed < 10; ++seed) {
    const Eigen::VectorXd x =
        c8::encode_planar(absolute.encode_observation(planar_scene(seed)), kObservations);
    const Eigen::Vector2d centre(uniform(rng, -80, 80), uniform(rng, -80, 80));
    // The identity, and k + 8 = k, to the last bit.
    CHECK(c8::act_planar(0, centre, x, kObservations) == x);
    for (int k = -8; k < 16; ++k) {
      CHECK(c8::act_planar(k, centre, x, kObservations) ==
            c8::act_planar(k + 8, centre, x, kObservations));
    }
    for (int j = 0; j < 8; ++j) {
      for (int k = 0; k < 8; ++k) {
        const Eigen::VectorXd two_steps =
            c8::act_planar(j, centre, c8::act_planar(k, centre, x, kObservations), kObservations);
        CHECK((two_steps - c8::act_planar(j + k, centre, x, kObservations))
                  .cwiseAbs()
                  .maxCoeff<Eigen::PropagateNaN>() < 1e-10);
      }
    }
  }
}

TEST_CASE("c8_planar_encoding_round_trips_without_a_wrap", "[unit]") {
  const AbsoluteRepresentation absolute;
  for (std::uint64_t seed = 0; seed < 10; ++seed) {
    const Eigen::VectorXd a = absolute.encode_actions(planar_scene(seed));
    const Eigen::VectorXd planar = c8::encode_planar(a, kActions);
    CHECK((c8::decode_planar(planar, kActions) - a).cwiseAbs().maxCoeff<Eigen::PropagateNaN>() <
          1e-12);
    CHECK((c8::encode_planar(c8::decode_planar(planar, kActions), kActions) - planar)
              .cwiseAbs()
              .maxCoeff<Eigen::PropagateNaN>() < 1e-12);
    // The network's (cos, sin) need not be unit length: the heading is its direction.
    Eigen::VectorXd scaled = planar;
    scaled.segment<2>(3) *= 0.3;
    CHECK(c8::decode_planar(scaled, kActions)[5] == Approx(a[5]).margin(1e-12));
  }
  // Headings of 179 and -179 deg are 2 deg apart in the encoding, not 358 as rotation vectors.
  Eigen::VectorXd near(6), far(6);
  near << 0, 0, 0, 0, 0, 179.0 * kPi / 180.0;
  far << 0, 0, 0, 0, 0, -179.0 * kPi / 180.0;
  const c8::Layout one{1, 0, 0};
  CHECK((c8::encode_planar(near, one) - c8::encode_planar(far, one)).norm() < 0.04);
}

TEST_CASE("c8_planar_encoding_refuses_3d_poses_and_wrong_lengths", "[unit]") {
  Eigen::VectorXd tilted(6);
  tilted << 0, 0, 0, 0.1, 0, 0.5;
  HC_CHECK_THROWS(c8::encode_planar(tilted, c8::Layout{1, 0, 0}), InvalidArgument,
                  Catch::Contains("not a rotation about z") && Catch::Contains("--head ddpm"));
  HC_CHECK_THROWS(c8::encode_planar(Eigen::VectorXd::Zero(7), c8::Layout{1, 0, 0}), InvalidArgument,
                  Catch::Contains("length 7, expected 6"));
  HC_CHECK_THROWS(c8::decode_planar(Eigen::VectorXd::Zero(6), c8::Layout{1, 0, 0}), InvalidArgument,
                  Catch::Contains("length 6, expected 5"));
  HC_CHECK_THROWS(
      c8::act_planar(1, Eigen::Vector2d::Zero(), Eigen::VectorXd::Zero(4), c8::Layout{1, 0, 0}),
      InvalidArgument, Catch::Contains("length 4, expected 5"));
}

TEST_CASE("c8_augmented_data_is_c8_invariant", "[unit]") {
  const AbsoluteRepresentation absolute;
  const Eigen::Vector2d centre(0.0, -60.0);
  Eigen::MatrixXd data(c8::Layout{4, 0, 0}.planar_size(), 5);
  for (int j = 0; j < 5; ++j)
    data.col(j) = c8::encode_planar(absolute.encode_actions(planar_scene(j)), kActions);
  const Eigen::MatrixXd orbit = c8::orbit(data, centre, kActions);
  REQUIRE(orbit.cols() == 40);
  // Moving every augmented sample by g_j gives the same set: column 8 i + k goes to 8 i + k + j.
  for (int j = 1; j < 8; ++j) {
    for (int i = 0; i < 5; ++i) {
      for (int k = 0; k < 8; ++k) {
        const Eigen::VectorXd moved = c8::act_planar(j, centre, orbit.col(8 * i + k), kActions);
        CHECK((moved - orbit.col(8 * i + (k + j) % 8)).cwiseAbs().maxCoeff<Eigen::PropagateNaN>() <
              1e-10);
      }
    }
  }
  // So its mean position is the centre and its mean heading zero, whatever the data.
  const Eigen::VectorXd mean = orbit.rowwise().mean();
  for (int p = 0; p < 4; ++p) {
    CHECK((mean.segment<2>(5 * p) - centre).norm() < 1e-9);
    CHECK(mean.segment<2>(5 * p + 3).norm() < 1e-12);
  }
}

TEST_CASE("c8ddpm_trains_on_8x_the_budget_and_refuses_what_it_cannot_encode", "[unit]") {
  std::vector<Scene> scenes;
  for (std::uint64_t s = 0; s < 6; ++s) scenes.push_back(planar_scene(s));
  PolicyConfig config = test::small_config(HeadKind::c8ddpm, "absolute", 0);
  config.c8_centre_y = -60.0;
  const LearnedPolicy policy = train_policy(config, scenes, 3);
  CHECK(policy.config().steps == training_budget(8 * 6));
  CHECK(policy.config().c8_centre_y == -60.0);
  CHECK(policy.config().to_text().find("c8_centre_y=-60") != std::string::npos);
  // The sampled chunk is planar: the decoder writes rotations about z only.
  const Eigen::VectorXd a = policy.action_vector(scenes[0], 4);
  REQUIRE(a.size() == 24);
  for (int k = 0; k < 4; ++k) CHECK(a.segment<2>(6 * k + 3).norm() == 0.0);
  // Other heads' config text does not name a centre (their Table 1 hashes stay as they were).
  CHECK(test::small_config(HeadKind::ddpm, "absolute", 1).to_text().find("c8_centre") ==
        std::string::npos);

  // The rectified-flow control on the same encoding: its own kind, the same 8x budget.
  PolicyConfig flow = config;
  flow.head = HeadKind::c8flow_planar;
  const LearnedPolicy flow_policy = train_policy(flow, scenes, 3);
  CHECK(flow_policy.head().kind() == HeadKind::c8flow_planar);
  CHECK(flow_policy.config().steps == training_budget(8 * 6));
  CHECK(flow_policy.action_vector(scenes[0], 4).size() == 24);

  config.steps = 1;
  config.representation = "hand_centric";
  HC_CHECK_THROWS(train_policy(config, scenes, 3), InvalidArgument,
                  Catch::Contains("--repr absolute"));
  config.representation = "absolute";
  std::vector<Scene> tilted = scenes;
  Twist tilt;
  tilt << 1, 2, 3, 0.3, 0, 0;
  tilted[2].world_T_hand_chunk[1] = RigidTransform::exp(tilt);
  HC_CHECK_THROWS(train_policy(config, tilted, 3), InvalidArgument,
                  Catch::Contains("not a rotation about z"));
  config.c8_centre_x = 1e7;
  HC_CHECK_THROWS(config.validate(), InvalidArgument, Catch::Contains("c8_centre_x"));
}

TEST_CASE("act_planar_float_is_act_planar_rounded_to_the_last_bit", "[unit]") {
  const AbsoluteRepresentation absolute;
  const Eigen::Vector2d centre(13.25, -60.0);
  for (std::uint64_t seed = 0; seed < 10; ++seed) {
    const Eigen::VectorXd x =
        c8::encode_planar(absolute.encode_observation(planar_scene(seed)), kObservations);
    for (int k = -1; k < 9; ++k) {
      Eigen::VectorXf out(kObservations.planar_size());
      c8::act_planar_float(k, centre, x, kObservations, out);
      CHECK(out == c8::act_planar(k, centre, x, kObservations).cast<float>());
    }
  }
  Eigen::VectorXf short_out(3);
  HC_CHECK_THROWS(
      c8::act_planar_float(1, centre, Eigen::VectorXd::Zero(kObservations.planar_size()),
                           kObservations, short_out),
      InvalidArgument, Catch::Contains("the output vector of length 3"));
}

namespace {

// The bytes of a planar C8 head trained 5 steps on minibatches of the set's columns: through
// train_step on the copied columns, or through train_step_on with `observations_for_lookup` as
// the set's observations (the trainer's call, answered from the head's encoding of the set).
std::string c8_head_bytes_after_steps(HeadKind kind, const Eigen::MatrixXd& actions,
                                      const Eigen::MatrixXd& observations, bool through_the_set,
                                      const Eigen::MatrixXf& observations_for_lookup) {
  PolicyConfig config = test::small_config(kind, "absolute", 0);
  config.hand_points = 2;
  config.world_points = 1;
  config.history_length = 2;
  config.chunk_length = 4;
  config.action_dimension = static_cast<int>(actions.rows());
  config.observation_dimension = static_cast<int>(observations.rows());
  config.batch_size = 8;
  const std::unique_ptr<Head> head = make_head(config);
  std::mt19937_64 rng(11);
  head->prepare(actions, observations, rng);
  const Eigen::MatrixXf set_actions = actions.cast<float>();
  const Eigen::MatrixXf set_observations = observations.cast<float>();
  Eigen::MatrixXf batch_actions(actions.rows(), 8), batch_observations(observations.rows(), 8);
  std::vector<Eigen::Index> columns(8);
  for (int step = 0; step < 5; ++step) {
    for (int j = 0; j < 8; ++j) {
      columns[static_cast<std::size_t>(j)] = static_cast<Eigen::Index>(rng() % actions.cols());
      batch_actions.col(j) = set_actions.col(columns[static_cast<std::size_t>(j)]);
      batch_observations.col(j) = set_observations.col(columns[static_cast<std::size_t>(j)]);
    }
    if (through_the_set) {
      head->train_step_on(Minibatch{set_actions, observations_for_lookup, columns, batch_actions,
                                    batch_observations},
                          rng);
    } else {
      head->train_step(batch_actions, batch_observations, rng);
    }
  }
  ByteWriter out;
  head->write(out);
  return out.bytes();
}

}  // namespace

TEST_CASE("planar_c8_heads_train_the_same_bits_from_their_encoded_set", "[unit]") {
  const AbsoluteRepresentation absolute;
  Eigen::MatrixXd actions(24, 12), observations(3 * 6 + 9, 12);
  for (int j = 0; j < 12; ++j) {
    const Scene scene = planar_scene(static_cast<std::uint64_t>(j));
    actions.col(j) = absolute.encode_actions(scene);
    observations.col(j) = absolute.encode_observation(scene);
  }
  const Eigen::MatrixXf set_observations = observations.cast<float>();
  for (const HeadKind kind : {HeadKind::c8ddpm, HeadKind::c8flow_planar}) {
    INFO(to_string(kind));
    const std::string copied =
        c8_head_bytes_after_steps(kind, actions, observations, false, set_observations);
    CHECK(c8_head_bytes_after_steps(kind, actions, observations, true, set_observations) == copied);
    // Planted fault: a set whose column 3 differs in one float's last bit from the columns
    // copied out. The head reads its encoding of the set, so its weights move away.
    Eigen::MatrixXf nudged = set_observations;
    nudged(0, 3) = std::nextafter(nudged(0, 3), 1e9f);
    CHECK(c8_head_bytes_after_steps(kind, actions, observations, true, nudged) != copied);
  }
}
