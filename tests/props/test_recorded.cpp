// Audits on a user's own recorded observations (props/observation/recorded.hpp): the cases come
// from the data, g moves what the data declare moving and leaves the held parts alone, and a
// world-frame part declared held (the planted fault: a goal pose filed with the images) turns an
// equivariant policy's verdict to NO. Files: JSON Lines and bad input; .npz files as NumPy
// writes them are read in tests/python_module/test_observations.py.
#include <catch2/catch.hpp>

#include <sstream>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/props/audit.hpp"
#include "handcentric/props/catch.hpp"
#include "handcentric/props/checks/check.hpp"
#include "handcentric/props/observation/generators.hpp"
#include "handcentric/props/observation/recorded.hpp"
#include "handcentric/props/checks/policy_audit.hpp"

using namespace handcentric;
using props::Group;
using props::RecordedObservations;
using props::Workspace;

namespace {

// A robot's log in a 1 m cell: the hand and a goal pose anywhere in [-0.8, 0.8]^2 x [0, 0.8],
// each with a short smooth chunk, an eye-in-hand point, a gripper width and a 2 x 3 "image".
RecordedObservations recorded_log(int count, bool goal_held) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Scene> scenes;
  for (int i = 0; i < count; ++i) {
    Scene s;
    const Rotation R = Rotation::exp(Eigen::Vector3d(u(rng), u(rng), u(rng)));
    const RigidTransform T0(R, Eigen::Vector3d(0.8 * u(rng), 0.8 * u(rng), 0.4 + 0.4 * u(rng)));
    Twist step;
    step << 0.01 * u(rng), 0.01 * u(rng), 0.01, 0.05 * u(rng), 0.0, 0.05;
    s.world_T_hand_history = {T0, T0 * RigidTransform::exp(-step)};
    for (int k = 1; k <= 4; ++k) s.world_T_hand_chunk.push_back(T0 * RigidTransform::exp(k * step));
    s.hand_points = {Eigen::Vector3d(0.0, 0.02 * u(rng), 0.1)};
    s.scalars = {{"gripper", 0.5 + 0.5 * u(rng)}};
    const RigidTransform goal(Rotation::exp(Eigen::Vector3d(0.0, 0.0, u(rng))),
                              Eigen::Vector3d(0.8 * u(rng), 0.8 * u(rng), 0.1));
    auto image = std::make_shared<HeldArray>();
    image->shape = {2, 3};
    for (int p = 0; p < 6; ++p) image->values.push_back(0.5 + 0.5 * u(rng));
    image->float32 = true;
    s.held = {{"wrist", image}};
    if (goal_held) {
      // The planted fault: the goal's world-frame matrix filed as a held array, so that the
      // audit leaves it where it was while it moves the hand.
      auto matrix = std::make_shared<HeldArray>();
      matrix->shape = {4, 4};
      const Eigen::Matrix<double, 4, 4, Eigen::RowMajor> M = goal.matrix();
      matrix->values.assign(M.data(), M.data() + 16);
      s.held.emplace_back("goal", matrix);
    } else {
      s.extra_poses = {{"goal", goal}};
    }
    scenes.push_back(std::move(s));
  }
  return props::recorded_observations(std::move(scenes), "a test log");
}

RigidTransform recorded_goal(const Scene& o) {
  for (const auto& [name, T] : o.extra_poses)
    if (name == "goal") return T;
  for (const auto& [name, array] : o.held) {
    if (name != "goal") continue;
    Eigen::Matrix4d M;
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) M(r, c) = array->values[static_cast<std::size_t>(4 * r + c)];
    return RigidTransform::from_matrix(M);
  }
  throw InvalidArgument("no goal");
}

// A hand-centric policy that steps toward its goal seen from the hand, scaled by the gripper
// width and the image's mean: equivariant exactly when everything it reads moves as it should.
class RecordedGoalPolicy final : public props::NoisyPolicy {
 public:
  std::string name() const override { return "goal_seeking"; }
  Eigen::Index noise_dimension() const override { return 1; }
  std::vector<RigidTransform> act(const Scene& o, const Eigen::VectorXd& noise) const override {
    const RigidTransform& T0 = o.world_T_hand0();
    const RigidTransform hand_T_goal = T0.inverse() * recorded_goal(o);
    double brightness = 0.0;
    for (const double v : o.held.front().second->values) brightness += v;
    Twist step;
    step << 0.1 * hand_T_goal.translation() * o.scalars.front().second * brightness,
        0.1 * hand_T_goal.rotation().log() + Eigen::Vector3d(0.0, 0.0, 0.01 * noise(0));
    std::vector<RigidTransform> chunk;
    RigidTransform T = T0;
    for (int k = 0; k < 3; ++k) chunk.push_back(T = T * RigidTransform::exp(step));
    return chunk;
  }
};

props::Verdict audit_goal_policy(const RecordedObservations& log, Group group,
                                 std::optional<Workspace> box = std::nullopt) {
  props::CheckOptions options;
  options.cases = 200;
  options.shape.max_world_points = 0;
  options.shape.recorded = std::make_shared<RecordedObservations>(log);
  options.shape.workspace = box;
  return props::check_policy_equivariance(RecordedGoalPolicy(), group, options);
}

}  // namespace

TEST_CASE("recorded_cases_are_the_datas_observations_and_g_leaves_the_held_parts_alone",
          "[property]") {
  const RecordedObservations log = recorded_log(20, false);
  props::SceneShape shape;
  shape.recorded = std::make_shared<RecordedObservations>(log);
  props::require_property("from the data", [&] {
    // Not a structured binding: clang 14 cannot capture one in the lambda below.
    const std::pair<Scene, RigidTransform> drawn = *props::recorded_case(shape, Group::se3);
    const Scene& o = drawn.first;
    const RigidTransform& g = drawn.second;
    const auto same = [&](const Scene& s) {
      return s.world_T_hand0().matrix() == o.world_T_hand0().matrix();
    };
    RC_ASSERT(std::any_of(log.scenes.begin(), log.scenes.end(), same));
    const Scene moved = g * o;
    RC_ASSERT(moved.held.front().second == o.held.front().second);  // the same array
    RC_ASSERT(moved.scalars == o.scalars);
    RC_ASSERT(moved.extra_poses.front().second.matrix().isApprox(
        (g * o.extra_poses.front().second).matrix()));
  });
}

TEST_CASE("a_policy_on_recorded_observations_is_equivariant_and_a_world_part_filed_as_held_is_not",
          "[property]") {
  const RecordedObservations log = recorded_log(30, false);
  for (const Group group : props::all_groups()) {
    INFO(props::to_string(group));
    const props::Verdict right = audit_goal_policy(log, group);
    CHECK(right.invariant);
    CHECK(right.cases > 100);
    CHECK_THAT(right.note, Catch::Matchers::Contains("30 recorded observations (a test log)"));
  }
  // The mutant: the goal filed under "held" stays put while the hand moves.
  const RecordedObservations misfiled = recorded_log(30, true);
  for (const Group group : props::all_groups()) {
    INFO(props::to_string(group));
    const props::Verdict wrong = audit_goal_policy(misfiled, group);
    CHECK_FALSE(wrong.invariant);
    REQUIRE(wrong.witness);
    CHECK_THAT(props::format_witness(*wrong.witness),
               Catch::Matchers::Contains("held array 'goal': (4, 4) float64 (unchanged by g)"));
  }
}

TEST_CASE("recorded_representation_audits_see_the_datas_chunks", "[property]") {
  props::AuditOptions audit;
  audit.cases = 150;
  audit.groups = {Group::translation, Group::rotation};
  audit.observations = std::make_shared<RecordedObservations>(recorded_log(25, false));
  const auto results = props::audit_builtins({"hand_centric", "absolute"}, audit);
  for (const props::Verdict& v : results[0].verdicts) CHECK(v.invariant);
  for (const props::Verdict& v : results[1].verdicts) {
    if (v.component == props::Component::actions) CHECK_FALSE(v.invariant);
  }
  // Without chunks, a representation has nothing to encode: refused, not audited on T_1 = T_0.
  RecordedObservations no_chunks = recorded_log(5, false);
  std::vector<Scene> scenes = no_chunks.scenes;
  for (Scene& s : scenes) s.world_T_hand_chunk.clear();
  audit.observations = std::make_shared<RecordedObservations>(
      props::recorded_observations(std::move(scenes), "chunkless"));
  CHECK_FALSE(audit.observations->has_chunks);
  CHECK_THROWS_WITH(props::audit_builtins({"hand_centric"}, audit),
                    Catch::Matchers::Contains("record no action chunk") &&
                        Catch::Matchers::Contains("'chunk' (K, 4, 4)"));
}

TEST_CASE("recorded_cases_in_a_workspace_keep_g_o_inside_it", "[property]") {
  const Workspace cell{Eigen::Vector3d(-1.0, -1.0, -0.2), Eigen::Vector3d(1.0, 1.0, 1.0)};
  const Workspace loose{cell.min.array() - 1e-9, cell.max.array() + 1e-9};
  props::SceneShape shape;
  shape.recorded = std::make_shared<RecordedObservations>(recorded_log(20, false));
  shape.workspace = cell;
  for (const Group group : props::all_groups()) {
    INFO(props::to_string(group));
    int moved_away = 0;
    props::require_property("inside", [&] {
      const auto [o, g] = *props::recorded_case(shape, group);
      RC_ASSERT(loose.contains(g * o));
      if (!g.matrix().isIdentity(1e-6)) ++moved_away;
    });
    CHECK(moved_away > 50);  // turned back toward the identity, not collapsed onto it
    CHECK(audit_goal_policy(*shape.recorded, group, cell).invariant);
  }
  const Workspace small{Eigen::Vector3d::Constant(-0.1), Eigen::Vector3d::Constant(0.1)};
  CHECK_THROWS_WITH(audit_goal_policy(*shape.recorded, Group::se3, small),
                    Catch::Matchers::Contains("lies outside the workspace"));
}

TEST_CASE("json_lines_observations_are_read_and_bad_ones_refused_with_the_line_and_the_fix",
          "[unit]") {
  const std::string pose = "[[1,0,0,0.1],[0,1,0,0.2],[0,0,1,0.3],[0,0,0,1]]";
  std::istringstream good("{\"history\": [" + pose + "], \"chunk\": [" + pose + "," + pose +
                          "], \"world_points\": [[1,2,3]], \"extra_poses\": {\"goal\": " + pose +
                          "}, \"scalars\": {\"gripper\": 0.5}, \"held\": {\"ids\": [3, 1, 4]}}\n\n"
                          "{\"history\": [" +
                          pose + "], \"chunk\": [" + pose +
                          "], \"extra_poses\": {\"goal\": " + pose +
                          "}, \"scalars\": {\"gripper\": 0.7}, \"held\": {\"ids\": [1, 5, 9]}}\n");
  const RecordedObservations read = props::observations_from_json_lines(good, "log.jsonl");
  REQUIRE(read.scenes.size() == 2);
  CHECK(read.has_chunks);
  CHECK(read.has_world_points());
  CHECK(read.scenes[0].world_T_hand_chunk.size() == 2);
  CHECK(read.scenes[1].held.front().second->values == std::vector<double>{1, 5, 9});
  CHECK(read.scenes[0].extra_poses.front().second.translation() == Eigen::Vector3d(0.1, 0.2, 0.3));

  auto refused = [](const std::string& text) {
    std::istringstream in(text);
    try {
      (void)props::observations_from_json_lines(in, "log.jsonl");
    } catch (const InvalidArgument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  CHECK_THAT(refused("{\"history\": [" + pose + "]\n"),
             Catch::Matchers::Contains("line 1 is not JSON"));
  CHECK_THAT(refused("{\"chunk\": [" + pose + "]}\n"), Catch::Matchers::Contains("no 'history'"));
  CHECK_THAT(refused("{\"history\": [[[1,0,0,0],[0,2,0,0],[0,0,1,0],[0,0,0,1]]]}\n"),
             Catch::Matchers::Contains("not a rigid transform"));
  CHECK_THAT(refused("{\"history\": [" + pose + "], \"world_points\": [[1,2,3],[4,5]]}\n"),
             Catch::Matchers::Contains("ragged"));
  CHECK_THAT(refused("{\"history\": [" + pose + "], \"velocity\": [1,2,3]}\n"),
             Catch::Matchers::Contains("part 'velocity'") &&
                 Catch::Matchers::Contains("the parts are history"));
  CHECK_THAT(refused("{\"history\": [" + pose + "], \"scalars\": {\"w\": 1}}\n{\"history\": [" +
                     pose + "]}\n"),
             Catch::Matchers::Contains("observation 1 names") &&
                 Catch::Matchers::Contains("every observation carries the same parts"));
  CHECK_THAT(refused("\n"), Catch::Matchers::Contains("are empty"));
  CHECK_THAT(refused("{\"history\": [" + pose + "], \"held\": {\"img\": [1e999]}}\n"),
             Catch::Matchers::Contains("not JSON") || Catch::Matchers::Contains("non-finite"));
  CHECK_THROWS_AS(props::read_observations("/no/such/file.jsonl"), FileError);
  CHECK_THROWS_WITH(props::read_observations("data.csv"),
                    Catch::Matchers::Contains("neither .jsonl nor .npz"));
}
