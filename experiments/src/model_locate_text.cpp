// locate_text and locate_json: a ModelLocation as python/handcentric/locate.py's locate_text
// prints it, and as JSON in the shape of its locate_json.
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "handcentric/core/format.hpp"
#include "handcentric/experiments/model_locate.hpp"
#include "handcentric/props/tolerance.hpp"

namespace handcentric::experiments {
namespace {

std::string locate_number(double x) {
  return format_significant(x, 3);
}

std::string locate_vector(const Eigen::Vector3d& v) {
  return "[" + format_significant(v.x()) + ", " + format_significant(v.y()) + ", " +
         format_significant(v.z()) + "]";
}

std::string locate_label(const std::string& name, int call) {
  return name + "[" + std::to_string(call) + "]";
}

std::string locate_padded(const std::string& text, std::size_t width) {
  return text.size() >= width ? text : text + std::string(width - text.size(), ' ');
}

std::string locate_rule() {
  char text[128];
  std::snprintf(text, sizeof text,
                "error <= REL (1 + c), or <= %g r with r <= sqrt(u) (1 + c); c the output's size",
                props::kRoundingMultiple);
  return text;
}

nlohmann::ordered_json locate_number_json(double x) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  return x;
}

}  // namespace

std::string locate_text(const ModelLocation& r) {
  // "layer" or "stage": what one row is (ModelLocation::watched without its plural s).
  const std::string row_word = r.watched.substr(0, r.watched.size() - 1);
  std::size_t width = 5;
  for (const LocatedLayer& layer : r.layers)
    width = std::max(width, locate_label(layer.name, layer.call).size());
  std::ostringstream out;
  const LocatedLayer* first = r.first_break();
  out << "locate " << r.policy << " under " << props::to_string(r.group) << " ("
      << props::to_string(r.view) << ", seed " << r.seed << ", " << r.cases << " cases): "
      << (first ? "first break at '" + first->name + "'" : "no " + row_word + " breaks its kind")
      << "\n";
  out << "   " << locate_padded(row_word, width) << "  " << locate_padded("kind", 8) << "  "
      << locate_padded("verdict", 11) << "  " << locate_padded("error", 9) << "  case\n";
  for (const LocatedLayer& layer : r.layers) {
    const char* mark = &layer == first ? ">> " : (layer.breaks ? "!  " : "   ");
    std::string line = mark + locate_padded(locate_label(layer.name, layer.call), width) + "  " +
                       locate_padded(to_string(layer.kind), 8) + "  " +
                       locate_padded(layer.verdict, 11) + "  " +
                       locate_padded(locate_number(layer.error), 9) + "  " +
                       (layer.first_case ? std::to_string(layer.first_case) : "");
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out << line << "\n";
  }
  if (r.witness) {
    const LocateWitness& w = *r.witness;
    out << "witness: " << locate_label(w.name, w.call) << " in case " << w.case_number
        << ", g: r = " << locate_vector(w.g.rotation().log())
        << ", p = " << locate_vector(w.g.translation()) << "; there error "
        << locate_number(w.case_error) << " > tolerance " << locate_number(w.tolerance)
        << ", the output's size c = " << locate_number(w.scale) << "\n";
  }
  out << "the policy's chunk: " << (r.chunk_equivariant ? "equivariant" : "NOT equivariant")
      << " (error " << locate_number(r.chunk_error)
      << (r.chunk_first_case ? ", first broken in case " + std::to_string(r.chunk_first_case) : "")
      << ")\n";
  char rel[64];
  std::snprintf(rel, sizeof rel, "REL = %g, u = %g", r.relative_tolerance, r.unit_roundoff);
  out << "tolerance: " << locate_rule() << "; " << rel << "\n";
  return out.str();
}

std::string locate_json(const std::vector<ModelLocation>& locations) {
  nlohmann::ordered_json all = nlohmann::ordered_json::array();
  for (const ModelLocation& r : locations) {
    nlohmann::ordered_json j;
    j["policy"] = r.policy;
    j["group"] = props::to_string(r.group);
    j["view"] = props::to_string(r.view);
    j["seed"] = r.seed;
    j["cases"] = r.cases;
    j["near_identity_cases"] = r.near_identity_cases;
    j["watched"] = r.watched;
    nlohmann::ordered_json layers = nlohmann::ordered_json::array();
    for (const LocatedLayer& layer : r.layers) {
      nlohmann::ordered_json row;
      row["name"] = layer.name;
      row["call"] = layer.call;
      row["kind"] = to_string(layer.kind);
      row["verdict"] = layer.verdict;
      row["breaks"] = layer.breaks;
      row["error"] = locate_number_json(layer.error);
      row["case"] = layer.first_case ? nlohmann::ordered_json(layer.first_case) : nullptr;
      row["shape"] = {layer.rows, layer.columns};
      row["rounding_response"] = locate_number_json(layer.rounding_response);
      if (!layer.note.empty()) row["note"] = layer.note;
      layers.push_back(std::move(row));
    }
    j[r.watched] = std::move(layers);
    const LocatedLayer* first = r.first_break();
    j["first_break"] = first ? nlohmann::ordered_json(first->name) : nullptr;
    if (r.witness) {
      const LocateWitness& w = *r.witness;
      nlohmann::ordered_json g = nlohmann::ordered_json::array();
      const Eigen::Matrix4d M = w.g.matrix();
      for (int i = 0; i < 4; ++i)
        for (int c = 0; c < 4; ++c) g.push_back(M(i, c));
      j["witness"] = {{"name", w.name},
                      {"call", w.call},
                      {"verdict", w.verdict},
                      {"case", w.case_number},
                      {"g", std::move(g)},
                      {"error", locate_number_json(w.error)},
                      {"case_error", locate_number_json(w.case_error)},
                      {"tolerance", locate_number_json(w.tolerance)},
                      {"scale", locate_number_json(w.scale)}};
    } else {
      j["witness"] = nullptr;
    }
    j["chunk"] = {{"equivariant", r.chunk_equivariant},
                  {"error", locate_number_json(r.chunk_error)},
                  {"case", r.chunk_first_case ? nlohmann::ordered_json(r.chunk_first_case)
                                              : nlohmann::ordered_json(nullptr)}};
    j["tolerance"] = {{"relative", r.relative_tolerance},
                      {"unit_roundoff", r.unit_roundoff},
                      {"rounding_multiple", props::kRoundingMultiple},
                      {"rule", locate_rule()}};
    all.push_back(std::move(j));
  }
  return nlohmann::ordered_json{{"locate", std::move(all)}}.dump(2) + "\n";
}

}  // namespace handcentric::experiments
