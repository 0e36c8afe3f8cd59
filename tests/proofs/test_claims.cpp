// The claims: every certificate verifies, and each is seen failing on a planted fault (a mutated
// claim), so that no certificate is vacuous.
#include <catch2/catch.hpp>

#include <algorithm>
#include <random>
#include <set>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/proofs/claims.hpp"
#include "handcentric/proofs/flows.hpp"
#include "handcentric/proofs/quaternion_rotation.hpp"
#include "handcentric/proofs/rational_rotation.hpp"

using namespace handcentric;
using namespace handcentric::proofs;

namespace {

const std::vector<Claim>& claims() {
  static const std::vector<Claim> all = paper_claims();
  return all;
}

const Claim& claim(const std::string& id) {
  const auto it =
      std::find_if(claims().begin(), claims().end(), [&](const Claim& c) { return c.id == id; });
  if (it == claims().end()) throw InvalidArgument("no claim with id '" + id + "'");
  return *it;
}

bool identity_holds(const Flow& flow, Group group) {
  return certify_identity(moved(flow), unmoved(flow), generic_instance(group)).verified;
}

// A small integer in [-2, 2] from the seeded generator (no std::*_distribution: same bits
// everywhere).
long small(std::mt19937_64& rng) {
  return static_cast<long>(rng() % 5) - 2;
}

ExactPose random_rational_pose(std::mt19937_64& rng) {
  long q[4] = {small(rng), small(rng), small(rng), small(rng)};
  if (q[0] == 0 && q[1] == 0 && q[2] == 0 && q[3] == 0) q[0] = 1;
  return ExactPose{rational_rotation(q[0], q[1], q[2], q[3]),
                   column(small(rng), small(rng), small(rng))};
}

// `count` seeded exact witnesses: T~, T_0, T_{-h}, T_k random rational poses, rational points and
// eps.
std::vector<Instance> rational_witnesses(std::uint64_t seed, int count) {
  std::mt19937_64 rng(seed);
  std::vector<Instance> witnesses;
  for (int i = 0; i < count; ++i) {
    Instance x;
    x.g = random_rational_pose(rng);
    x.scene.history = {random_rational_pose(rng), random_rational_pose(rng)};
    x.scene.chunk = {random_rational_pose(rng)};
    x.scene.world_points = {column(small(rng), small(rng), small(rng))};
    x.scene.hand_points = {column(small(rng), small(rng), small(rng))};
    x.eps = column(small(rng), small(rng), small(rng));
    x.t = GiNaC::numeric(1, 3);
    witnesses.push_back(x);
  }
  return witnesses;
}

int verified_counterexamples(const Flow& flow, const std::vector<Instance>& witnesses) {
  int verified = 0;
  for (const Instance& w : witnesses) {
    verified +=
        certify_counterexample(moved(flow), unmoved(flow), w, "seeded witness").verified ? 1 : 0;
  }
  return verified;
}

}  // namespace

TEST_CASE("every_certificate_of_the_paper_verifies", "[proofs]") {
  const std::vector<ClaimOutcome> outcomes = certify_all(claims());
  for (const ClaimOutcome& outcome : outcomes) {
    INFO(outcome.id << ": " << outcome.result.detail);
    CHECK(outcome.result.verified);
    CHECK(outcome.result.witness.empty() == (outcome.kind == ClaimKind::identity));
  }
  CHECK(count_verified(outcomes) == static_cast<int>(outcomes.size()));
}

TEST_CASE("every_claim_the_issue_lists_is_registered_once_with_its_kind", "[proofs]") {
  std::set<std::string> ids;
  for (const Claim& c : claims()) {
    CHECK(ids.insert(c.id).second);
    CHECK_FALSE(c.statement.empty());
  }
  const std::vector<std::pair<std::string, ClaimKind>> expected = {
      {"Sec. 3.2 eq. (9)", ClaimKind::identity},
      {"A.3 eq. (23)", ClaimKind::identity},
      {"A.3 eq. (26)", ClaimKind::identity},
      {"A.2 eq. (16), translations", ClaimKind::identity},
      {"Sec. 3.1 Lemma 1, eq. (8)", ClaimKind::identity},
      {"Sec. 3.2 Lemma 2 with eq. (9)", ClaimKind::identity},
      {"A.1 eq. (11), translations", ClaimKind::counterexample},
      {"A.1 eq. (11), rotations", ClaimKind::counterexample},
      {"A.1 eq. (13)", ClaimKind::counterexample},
      {"A.2 eq. (16), rotations", ClaimKind::counterexample},
      {"A.2 eq. (18)", ClaimKind::counterexample},
      {"A.4 eq. (30), translations", ClaimKind::counterexample},
      {"A.4 eq. (30), rotations", ClaimKind::counterexample},
      {"Sec. 2.1 vs A.2 eq. (14)", ClaimKind::identity},
      {"A.4 eq. (27) as printed", ClaimKind::counterexample},
      {"A.4 eq. (30), middle: p~ term as printed", ClaimKind::counterexample},
      {"Sec. 5 vs A.4, rotations in distribution", ClaimKind::identity},
  };
  for (const auto& [id, kind] : expected) {
    INFO(id);
    CHECK(claim(id).kind == kind);
  }
}

TEST_CASE("mutant_claim_that_relative_is_rotation_invariant_fails_the_identity_check", "[proofs]") {
  CHECK(identity_holds(with_noise(flows::relative_translation), Group::translations));
  CHECK_FALSE(identity_holds(with_noise(flows::relative_translation), Group::rotations));
  CHECK_FALSE(identity_holds(with_noise(flows::absolute_translation), Group::translations));
  CHECK_FALSE(identity_holds(ignoring_noise(flows::absolute_rotation_matrix), Group::rotations));
  CHECK_FALSE(identity_holds(with_noise(flows::actionflow_translation), Group::rotations));
  CHECK_FALSE(
      identity_holds(ignoring_noise(flows::inner_policy_input_third_person), Group::translations));
}

TEST_CASE("mutant_counterexamples_for_hand_centric_never_verify", "[proofs]") {
  const std::vector<Instance> witnesses = rational_witnesses(20261122, 25);
  CHECK(verified_counterexamples(with_noise(flows::hand_centric_translation), witnesses) == 0);
  CHECK(verified_counterexamples(ignoring_noise(flows::hand_centric_rotation_matrix), witnesses) ==
        0);
  CHECK(verified_counterexamples(ignoring_noise(flows::hand_centric_proprioception), witnesses) ==
        0);
  CHECK(verified_counterexamples(ignoring_noise(flows::inner_policy_input), witnesses) == 0);
  // The same witnesses do break the representations that are not invariant.
  CHECK(verified_counterexamples(with_noise(flows::relative_translation), witnesses) > 20);
  CHECK(verified_counterexamples(with_noise(flows::actionflow_translation), witnesses) > 20);
}

TEST_CASE("mutant_hand_centric_flows_fail_their_identities", "[proofs]") {
  // eq. (23) without R_0^T, eq. (26) with R_0 for R_0^T, eq. (9) with the product reversed.
  const Flow forgets_R0T = [](const ExactScene& s, const GiNaC::matrix& eps, const GiNaC::ex&) {
    return s.chunk[0].p.sub(s.history[0].p).sub(eps);
  };
  const Flow R0_for_R0T = [](const ExactScene& s, const GiNaC::matrix&, const GiNaC::ex&) {
    return s.history[0].R.mul(s.chunk[0].R);
  };
  const Flow reversed_product = [](const ExactScene& s, const GiNaC::matrix&, const GiNaC::ex&) {
    return (s.history[1] * s.history[0].inverse()).entries();
  };
  CHECK_FALSE(identity_holds(forgets_R0T, Group::rigid_motions));
  CHECK_FALSE(identity_holds(R0_for_R0T, Group::rotations));
  CHECK_FALSE(identity_holds(reversed_product, Group::rigid_motions));
}

TEST_CASE("mutant_non_orthonormal_rotations_break_the_hand_centric_identity", "[proofs]") {
  // eq. (23) relies on R~^T R~ = I: with M(q) in place of R(q) (no 1/|q|^2) it must fail.
  const Claim& eq23 = claim("A.3 eq. (23)");
  Instance unnormalized = generic_instance(Group::rigid_motions);
  const GiNaC::symbol w("w"), x("x"), y("y"), z("z");
  unnormalized.g.R = quaternion_rotation(w, x, y, z).mul_scalar(w * w + x * x + y * y + z * z);
  CHECK(certify_identity(eq23.lhs, eq23.rhs, generic_instance(Group::rigid_motions)).verified);
  CHECK_FALSE(certify_identity(eq23.lhs, eq23.rhs, unnormalized).verified);
}

TEST_CASE("mutant_lemma1_with_an_inner_action_that_moves_with_the_scene_is_not_equivariant",
          "[proofs]") {
  // If Ra_k depended on T~ (here Ra_k moved by T~ too), (T~ T_0) Ra_k' != T~ a_k.
  const ExactPose hand0_T_handk = generic_pose("a");
  const Side lhs = [hand0_T_handk](const Instance& i) {
    return ((i.g * i.scene.history[0]) * (i.g * hand0_T_handk)).entries();
  };
  const Side rhs = [hand0_T_handk](const Instance& i) {
    return (i.g * (i.scene.history[0] * hand0_T_handk)).entries();
  };
  CHECK_FALSE(certify_identity(lhs, rhs, generic_instance(Group::rigid_motions)).verified);
}

TEST_CASE("mutant_claims_fail_every_certificate", "[proofs]") {
  // Identities: the right-hand side plus one fresh symbol in its first entry must not verify.
  // Counterexamples: the witness compared with itself (lhs against lhs) must not verify.
  const GiNaC::symbol delta("delta");
  for (const Claim& c : claims()) {
    INFO(c.id);
    if (c.kind == ClaimKind::identity) {
      const Side rhs = c.rhs;
      const Side perturbed = [rhs, delta](const Instance& i) {
        GiNaC::matrix m = rhs(i);
        m(0, 0) = m(0, 0) + delta;
        return m;
      };
      CHECK_FALSE(certify_identity(c.lhs, perturbed, generic_instance(c.group)).verified);
    } else {
      CHECK_FALSE(certify_counterexample(c.lhs, c.lhs, c.witness, c.inputs).verified);
    }
  }
}

TEST_CASE("counterexample_with_a_symbolic_witness_is_a_typed_error", "[proofs]") {
  const Flow flow = with_noise(flows::absolute_translation);
  CHECK_THROWS_AS(certify_counterexample(moved(flow), unmoved(flow),
                                         generic_instance(Group::translations), "w"),
                  InvalidArgument);
  // A claim whose certificate throws is reported as not verified, with the error.
  Claim broken = claim("A.1 eq. (11), translations");
  broken.certify = [flow] {
    return certify_counterexample(moved(flow), unmoved(flow), generic_instance(Group::translations),
                                  "w");
  };
  const ClaimOutcome outcome = certify(broken);
  CHECK_FALSE(outcome.result.verified);
  CHECK_THAT(outcome.result.detail, Catch::Contains("symbols"));
}

TEST_CASE("exact_flows_agree_with_core_representations_on_rational_scenes", "[proofs]") {
  // The certificates are about the same formulas core implements: on rational scenes the exact
  // hand-centric and relative translations equal core's encodings (to rounding).
  const auto to_double = [](const GiNaC::ex& e) {
    return GiNaC::ex_to<GiNaC::numeric>(GiNaC::evalf(e)).to_double();
  };
  const auto to_pose = [&](const ExactPose& T) {
    Eigen::Matrix3d R;
    Eigen::Vector3d p;
    for (unsigned i = 0; i < 3; ++i) {
      for (unsigned j = 0; j < 3; ++j) R(i, j) = to_double(T.R(i, j));
      p(i) = to_double(T.p(i, 0));
    }
    return RigidTransform(Rotation::from_matrix(R), p);
  };
  const auto mismatches = [&](const Flow& exact, const Representation& core) {
    int bad = 0;
    for (const Instance& w : rational_witnesses(7, 10)) {
      Scene scene;
      scene.world_T_hand_history = {to_pose(w.scene.history[0])};
      scene.world_T_hand_chunk = {to_pose(w.scene.chunk[0])};
      const GiNaC::matrix e = exact(w.scene, column(0, 0, 0), 0);
      const Eigen::VectorXd a = core.encode_actions(scene);
      for (unsigned i = 0; i < 3; ++i) bad += std::abs(to_double(e(i, 0)) - a(i)) > 1e-12 ? 1 : 0;
    }
    return bad;
  };
  CHECK(mismatches(with_noise(flows::hand_centric_translation), HandCentricRepresentation()) == 0);
  CHECK(mismatches(with_noise(flows::relative_translation), RelativeRepresentation()) == 0);
  // Planted fault: the relative formula is not what core's hand_centric computes.
  CHECK(mismatches(with_noise(flows::relative_translation), HandCentricRepresentation()) > 0);
}
