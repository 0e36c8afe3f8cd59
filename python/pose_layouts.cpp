#include "pose_layouts.hpp"

namespace handcentric::python {
namespace {

// The layouts `width` numbers per pose may be, for the hint of an error.
std::string layouts_of_width(py::ssize_t width) {
  std::string out;
  for (const std::string& name : pose_format_names()) {
    if (name == "matrix") continue;  // (..., 4, 4), not a vector of 16
    const std::string parsed =
        name.find('<') == std::string::npos ? name : name.substr(0, name.find('<')) + "xyz";
    if (parse_pose_format(parsed, "action_format").width() == width)
      out += (out.empty() ? "" : ", ") + name;
  }
  return out;
}

// Poses -> rows of numbers in `format`, one after the other, into `out`.
void write_encoded(const std::vector<RigidTransform>& poses, const PoseFormat& format,
                   double* out) {
  for (const RigidTransform& pose : poses) {
    const Eigen::VectorXd v = encode_pose(pose, format);
    std::copy(v.data(), v.data() + v.size(), out);
    out += v.size();
  }
}

py::array_t<double> encoded(const std::vector<const std::vector<RigidTransform>*>& per_scene,
                            bool stacked, const PoseFormat& format, bool one_pose) {
  std::vector<py::ssize_t> shape;
  if (stacked) shape.push_back(static_cast<py::ssize_t>(per_scene.size()));
  if (!one_pose) shape.push_back(static_cast<py::ssize_t>(per_scene.front()->size()));
  if (format.kind == PoseFormat::Kind::matrix) {
    shape.push_back(4);
    shape.push_back(4);
  } else {
    shape.push_back(format.width());
  }
  py::array_t<double> a(shape);
  double* out = a.mutable_data();
  for (const auto* poses : per_scene) {
    write_encoded(*poses, format, out);
    out += static_cast<std::ptrdiff_t>(poses->size()) * format.width();
  }
  return a;
}

}  // namespace

py::array_t<double> history_in(const std::vector<const Scene*>& scenes, bool stacked,
                               const PoseFormat& format) {
  std::vector<const std::vector<RigidTransform>*> per_scene;
  for (const Scene* s : scenes) per_scene.push_back(&s->world_T_hand_history);
  if (!stacked) per_scene.resize(1);
  return encoded(per_scene, stacked, format, false);
}

py::array_t<double> extra_pose_in(const std::vector<const Scene*>& scenes, std::size_t index,
                                  bool stacked, const PoseFormat& format) {
  std::vector<std::vector<RigidTransform>> one;
  for (const Scene* s : scenes) one.push_back({s->extra_poses.at(index).second});
  std::vector<const std::vector<RigidTransform>*> per_scene;
  for (const auto& poses : one) per_scene.push_back(&poses);
  if (!stacked) per_scene.resize(1);
  return encoded(per_scene, stacked, format, true);
}

std::vector<std::vector<RigidTransform>> chunks_from(py::handle result, std::size_t rows,
                                                     bool stacked, const PoseFormat& format,
                                                     const std::string& what) {
  const auto a = real_array(result, what);
  const py::ssize_t lead = stacked ? 1 : 0;  // the batch axis
  const py::ssize_t B = static_cast<py::ssize_t>(rows);
  const bool matrix = format.kind == PoseFormat::Kind::matrix;
  const py::ssize_t ndim = lead + (matrix ? 3 : 2);
  const std::string batch = stacked ? std::to_string(B) + ", " : "";
  const std::string expected =
      "(" + batch + "K, " + (matrix ? "4, 4" : std::to_string(format.width())) + ")";
  bool right = a.ndim() == ndim && (!stacked || a.shape(0) == B) && a.shape(lead) >= 1;
  if (right && matrix) right = a.shape(lead + 1) == 4 && a.shape(lead + 2) == 4;
  if (right && !matrix) right = a.shape(lead + 1) == format.width();
  if (!right) {
    std::string hint;
    const py::ssize_t last = a.ndim() > 0 ? a.shape(a.ndim() - 1) : 0;
    if (matrix && a.ndim() == lead + 2 && !layouts_of_width(last).empty()) {
      hint = "; a chunk of pose vectors of " + std::to_string(last) +
             " numbers? name their layout: action_format= one of " + layouts_of_width(last);
    } else if (!matrix) {
      hint = " (action_format=\"" + format.name() + "\" has " + std::to_string(format.width()) +
             " numbers per pose)";
    }
    throw ShapeError(what + " has shape " + shape_of(a) +
                     (stacked ? " for a batch of " + std::to_string(B) + " observations" : "") +
                     "; expected " + expected +
                     (stacked ? ", one chunk per observation" : " with at least one pose") + hint);
  }
  const py::ssize_t K = a.shape(lead);
  const py::ssize_t per_row = K * format.width();
  std::vector<std::vector<RigidTransform>> out;
  for (py::ssize_t i = 0; i < (stacked ? B : 1); ++i) {
    // Per row, so that a NaN names its row (the batch is then asked row by row, batch.cpp, and
    // the audit names the case and the observation).
    const std::string row = stacked ? what + "[" + std::to_string(i) + "]" : what;
    const double* data = a.data() + i * per_row;
    require_finite(data, per_row, row);
    if (matrix) {
      out.push_back(loose_poses(data, K, row));
      continue;
    }
    std::vector<RigidTransform> chunk;
    for (py::ssize_t k = 0; k < K; ++k) {
      chunk.push_back(
          decode_pose(Eigen::Map<const Eigen::VectorXd>(data + k * format.width(), format.width()),
                      format, row + "[" + std::to_string(k) + "]"));
    }
    out.push_back(std::move(chunk));
  }
  return out;
}

py::array_t<double> encode_pose_array(py::handle poses, const std::string& format_name) {
  const PoseFormat format = parse_pose_format(format_name, "format");
  const auto a = real_array(poses, "poses");
  if (a.ndim() < 2 || a.shape(a.ndim() - 1) != 4 || a.shape(a.ndim() - 2) != 4)
    throw ShapeError("poses has shape " + shape_of(a) + "; expected (..., 4, 4)");
  require_finite(a.data(), a.size(), "poses");
  std::vector<py::ssize_t> shape(a.shape(), a.shape() + a.ndim() - 2);
  if (format.kind == PoseFormat::Kind::matrix) {  // the poses themselves, (..., 4, 4)
    shape.push_back(4);
    shape.push_back(4);
  } else {
    shape.push_back(format.width());
  }
  py::array_t<double> out(shape);
  const py::ssize_t count = a.size() / 16;
  for (py::ssize_t n = 0; n < count; ++n) {
    const Eigen::Matrix4d M =
        Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(a.data() + 16 * n);
    const Eigen::VectorXd v =
        encode_pose(RigidTransform::from_matrix(M), format);  // validated: a rotation
    std::copy(v.data(), v.data() + v.size(), out.mutable_data() + n * format.width());
  }
  return out;
}

py::array_t<double> decode_pose_array(py::handle vectors, const std::string& format_name) {
  const PoseFormat format = parse_pose_format(format_name, "format");
  const auto a = real_array(vectors, "vectors");
  const bool matrix = format.kind == PoseFormat::Kind::matrix;
  if (matrix && (a.ndim() < 2 || a.shape(a.ndim() - 1) != 4 || a.shape(a.ndim() - 2) != 4))
    throw ShapeError("vectors has shape " + shape_of(a) + "; matrix poses are (..., 4, 4)");
  if (!matrix && (a.ndim() < 1 || a.shape(a.ndim() - 1) != format.width())) {
    throw ShapeError("vectors has shape " + shape_of(a) + "; a pose in " + format.name() + " has " +
                     std::to_string(format.width()) + " numbers");
  }
  std::vector<py::ssize_t> shape(a.shape(), a.shape() + a.ndim() - (matrix ? 2 : 1));
  shape.push_back(4);
  shape.push_back(4);
  py::array_t<double> out(shape);
  const py::ssize_t count = a.size() / format.width();
  for (py::ssize_t n = 0; n < count; ++n) {
    const RigidTransform T = decode_pose(
        Eigen::Map<const Eigen::VectorXd>(a.data() + n * format.width(), format.width()), format,
        "vectors[" + std::to_string(n) + "]");
    const Eigen::Matrix4d M = T.matrix();
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) out.mutable_data()[16 * n + 4 * r + c] = M(r, c);
  }
  return out;
}

}  // namespace handcentric::python
