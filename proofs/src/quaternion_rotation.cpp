#include "handcentric/proofs/quaternion_rotation.hpp"

namespace handcentric::proofs {

GiNaC::matrix quaternion_rotation(const GiNaC::ex& w, const GiNaC::ex& x, const GiNaC::ex& y,
                                  const GiNaC::ex& z) {
  const GiNaC::ex norm2 = w * w + x * x + y * y + z * z;
  const GiNaC::matrix M{{w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)},
                        {2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)},
                        {2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z}};
  GiNaC::matrix R(3, 3);
  for (unsigned i = 0; i < 3; ++i) {
    for (unsigned j = 0; j < 3; ++j) R(i, j) = M(i, j) / norm2;
  }
  return R;
}

GiNaC::matrix generic_rotation(const std::string& name) {
  return quaternion_rotation(GiNaC::symbol(name + "_w"), GiNaC::symbol(name + "_x"),
                             GiNaC::symbol(name + "_y"), GiNaC::symbol(name + "_z"));
}

GiNaC::matrix generic_vector(const std::string& name) {
  return column(GiNaC::symbol(name + "_1"), GiNaC::symbol(name + "_2"), GiNaC::symbol(name + "_3"));
}

ExactPose generic_pose(const std::string& name) {
  return ExactPose{generic_rotation("q" + name), generic_vector("p" + name)};
}

}  // namespace handcentric::proofs
